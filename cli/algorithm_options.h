// The simplification options shared by every command that runs the simplifier (`simplify`,
// `lod`): one definition of their flags, help texts and defaults, one translation to
// SimplifyOptions / LoadOptions.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "qem/io.h"
#include "qem/simplify.h"

namespace qem::cli {

struct AlgorithmArgs {
  double threshold = 0, threshold_rel = 0;
  std::string weighting = to_string(SimplifyOptions{}.weighting);
  std::string placement = to_string(SimplifyOptions{}.placement);
  std::string inversion = to_string(SimplifyOptions{}.inversion);
  std::string scheme = to_string(SimplifyOptions{}.scheme);
  std::size_t greedy_below = SimplifyOptions{}.greedy_below_faces;
  unsigned threads = 0;
  double boundary_weight = SimplifyOptions{}.boundary_weight;
  double max_turn = SimplifyOptions{}.max_normal_turn_degrees;
  bool lock_border = false, allow_non_manifold = false;
  bool penalty_border = false;  // --boundary-weight given: GH97 §6's penalty instead of exact borders
  bool weld = false, no_weld = false;
  bool refit = false;         // --refit
  unsigned refit_rounds = 0;  // --refit-rounds (implies --refit); 0 = RefitOptions' default
  double refit_sample = 0;    // --refit-sample (implies --refit); 0 = every input vertex
  bool no_refit = false;      // --no-refit: not even the light refit of the default
  std::vector<std::string> attribute_weights;  // --attribute-weight KIND=W, ...
  /// --refit, --refit-rounds or --refit-sample given (rather than the default's light refit).
  bool refit_asked() const { return refit || refit_rounds > 0 || refit_sample > 0; }
};

/// The command line's default refit (a light one: `--refit-rounds 1 --refit-sample 2`), made
/// after every run with optimal placement unless --no-refit: one round on about 2 input vertices
/// per output vertex is the least refit that puts E under the best peer's on every benchmark case
/// (fewer points fit a noisy surface's noise), and it costs a small share of the run
/// (docs/benchmarks.md, "Refit variants"). Other placements keep their vertices where they put
/// them (endpoints stay input vertices). The library's SimplifyOptions default stays GH97 as
/// published (no refit).
inline constexpr unsigned kDefaultRefitRounds = 1;
inline constexpr double kDefaultRefitSample = 2;

/// Adds --threshold(-rel), --weighting, --placement, --scheme, --greedy-below, --threads,
/// --boundary-weight, --lock-border, --inversion, --max-turn, --allow-non-manifold, --weld,
/// --no-weld, --refit, --refit-rounds, --refit-sample, --no-refit to `sub`.
void add_algorithm_options(CLI::App* sub, AlgorithmArgs& args);

/// The algorithm part of SimplifyOptions (stop criteria are left to the caller), with the default
/// refit above. Throws qem::Error if --no-refit comes with a refit option.
SimplifyOptions to_simplify_options(const AlgorithmArgs& args);

LoadOptions to_load_options(const AlgorithmArgs& args);

}  // namespace qem::cli
