// The simplification options shared by every command that runs the simplifier (`simplify`,
// `lod`): one definition of their flags, help texts and defaults, one translation to
// SimplifyOptions / LoadOptions.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "qem/io.h"
#include "qem/simplify.h"

namespace qem::cli {

struct AlgorithmArgs {
  double threshold = 0, threshold_rel = 0;
  std::string weighting = "area", placement = "optimal", inversion = "forbid";
  std::string scheme = "passes";
  std::size_t greedy_below = SimplifyOptions{}.greedy_below_faces;
  unsigned threads = 0;
  double boundary_weight = SimplifyOptions{}.boundary_weight;
  double max_turn = SimplifyOptions{}.max_normal_turn_degrees;
  bool lock_border = false, allow_non_manifold = false;
  bool weld = false, no_weld = false;
  bool refit = false;         // --refit
  unsigned refit_rounds = 0;  // --refit-rounds (implies --refit); 0 = RefitOptions' default
  double refit_sample = 0;    // --refit-sample (implies --refit); 0 = every input vertex
};

/// Adds --threshold(-rel), --weighting, --placement, --scheme, --greedy-below, --threads,
/// --boundary-weight, --lock-border, --inversion, --max-turn, --allow-non-manifold, --weld,
/// --no-weld, --refit, --refit-rounds, --refit-sample to `sub`.
void add_algorithm_options(CLI::App* sub, AlgorithmArgs& args);

/// The algorithm part of SimplifyOptions (stop criteria are left to the caller).
SimplifyOptions to_simplify_options(const AlgorithmArgs& args);

LoadOptions to_load_options(const AlgorithmArgs& args);

}  // namespace qem::cli
