#include "algorithm_options.h"

#include <cmath>
#include <cstdlib>
#include <string>

#include "cli_util.h"

#include "qem/error.h"
#include "qem/refit.h"

namespace qem::cli {

void add_algorithm_options(CLI::App* sub, AlgorithmArgs& a) {
  sub->add_option("--threshold,-t", a.threshold,
                  "Pair threshold t of GH97 3.2 (model units): vertices closer than t are valid pairs, so "
                  "separate parts can join (0 = edges only)");
  sub->add_option("--threshold-rel", a.threshold_rel, "As --threshold, relative to the bounding-box diagonal");
  sub->add_option("--weighting", a.weighting, "Plane weighting: area (HG99), uniform (GH97), angle")
      ->check(CLI::IsMember(option_names<Weighting>()))
      ->capture_default_str();
  sub->add_option("--placement", a.placement,
                  "Where the new vertex goes: optimal (then segment, then endpoints), segment, midpoint, endpoints")
      ->check(CLI::IsMember(option_names<Placement>()))
      ->capture_default_str();
  sub->add_option("--scheme", a.scheme,
                  "Order of contractions: greedy (strictly cheapest first, GH97's heap) or passes (rank, sort, "
                  "contract each vertex at most once a pass; faster)")
      ->check(CLI::IsMember(option_names<Scheme>()))
      ->capture_default_str();
  sub->add_option("--greedy-below", a.greedy_below,
                  "With --scheme passes, finish in the greedy order below this many faces (0 = never)")
      ->capture_default_str();
  sub->add_option("--threads", a.threads, "Threads for the passes: re-costing pairs, and making contractions region by region (0 = all; same result)")
      ->capture_default_str();
  sub->add_option("--boundary-weight", a.boundary_weight,
                  "Borders as GH97 6's penalty instead of exact: weight of the boundary constraint planes, "
                  "times the squared edge length (0 = off). Without it, border vertices stay on the input's "
                  "borders (only ever at an input border vertex) and border corners are kept exactly")
      ->each([&a](const std::string&) { a.penalty_border = true; })
      ->capture_default_str();
  sub->add_flag("--lock-border", a.lock_border, "Boundary vertices never move (nor are removed)");
  sub->add_option("--attribute-weight", a.attribute_weights,
                  "Weight of an attribute's error against distance, as KIND=W (normal, uv, color, scalar; "
                  "repeat or separate by commas): a difference of 1/W costs as much as one bounding-box "
                  "diagonal (defaults: normal=" + json_number(AttributeWeights{}.normal) + ", uv=" +
                      json_number(AttributeWeights{}.tex_coord) + ", color=" + json_number(AttributeWeights{}.color) +
                      ", scalar=" + json_number(AttributeWeights{}.scalar) + ")")
      ->delimiter(',');
  sub->add_option("--inversion", a.inversion, "Contractions that flip a face: forbid, penalize, or off (GH97 6)")
      ->check(CLI::IsMember(option_names<InversionPolicy>()))
      ->capture_default_str();
  sub->add_option("--max-turn", a.max_turn, "A face normal turning by more than this (degrees, < 90) is a flip")
      ->capture_default_str();
  sub->add_flag("--allow-non-manifold", a.allow_non_manifold,
                "Do not check the link condition: edge collapses may create non-manifold edges");
  sub->add_flag("--weld", a.weld, "Merge exactly coincident vertices on load (default for STL)");
  sub->add_flag("--no-weld", a.no_weld, "Never weld on load, not even STL");
  sub->add_flag("--refit", a.refit,
                "After the last contraction, move the vertices to fit the input surface, faces fixed "
                "(Hoppe et al. 1993; lowers the error at the same face count, see `qem refit --help`), in " +
                    std::to_string(RefitOptions{}.rounds) +
                    " rounds and to every input vertex. Without any refit option, a light refit is made "
                    "(--refit-rounds " +
                    std::to_string(kDefaultRefitRounds) + " --refit-sample " +
                    std::to_string(int(kDefaultRefitSample)) +
                    ") when --placement is optimal; see --no-refit");
  sub->add_option("--refit-rounds", a.refit_rounds,
                  "Project-and-solve rounds of --refit (implies it; default " +
                      std::to_string(RefitOptions{}.rounds) + ")")
      ->check(CLI::Range(1u, 100u));
  sub->add_option("--refit-sample", a.refit_sample,
                  "Fit --refit to about this many input vertices per output vertex, every k-th along a "
                  "space-filling curve (implies --refit; 0 = all). 4-8 keep most of its gain; the time "
                  "saved grows with the input vertices per output vertex")
      ->check(CLI::Range(0.0, 1e6));
  sub->add_flag("--no-refit", a.no_refit,
                "No refit, not even the default's light one: every vertex stays where GH97 placed it");
}

namespace {

/// The value named by an option that IsMember(option_names<Enum>()) has already checked.
template <class Enum>
Enum parsed(const char* flag, const std::string& name) {
  Enum value{};
  if (!from_string(name, value)) throw Error(std::string(flag) + ": unknown value '" + name + "'");
  return value;
}

}  // namespace

SimplifyOptions to_simplify_options(const AlgorithmArgs& a) {
  SimplifyOptions opt;
  if (a.threshold_rel > 0) {
    opt.threshold = a.threshold_rel;
    opt.threshold_is_relative = true;
  } else {
    opt.threshold = a.threshold;
  }
  opt.weighting = parsed<Weighting>("--weighting", a.weighting);
  opt.placement = parsed<Placement>("--placement", a.placement);
  opt.inversion = parsed<InversionPolicy>("--inversion", a.inversion);
  opt.scheme = parsed<Scheme>("--scheme", a.scheme);
  opt.greedy_below_faces = a.greedy_below;
  opt.threads = a.threads;
  opt.boundary_weight = a.boundary_weight;
  opt.max_normal_turn_degrees = a.max_turn;
  opt.lock_border = a.lock_border;
  opt.exact_border = !a.penalty_border;
  opt.preserve_topology = !a.allow_non_manifold;
  for (const std::string& item : a.attribute_weights) {
    const std::size_t eq = item.find('=');
    const std::string kind = item.substr(0, eq);
    double* weight = kind == "normal" ? &opt.attribute_weights.normal
                     : kind == "uv"   ? &opt.attribute_weights.tex_coord
                     : kind == "color" ? &opt.attribute_weights.color
                     : kind == "scalar" ? &opt.attribute_weights.scalar
                                        : nullptr;
    char* end = nullptr;
    const double w = eq == std::string::npos ? -1 : std::strtod(item.c_str() + eq + 1, &end);
    if (!weight || eq == std::string::npos || !end || *end != 0 || !(w >= 0) || !std::isfinite(w))
      throw Error("--attribute-weight: expected KIND=W with KIND normal, uv, color or scalar and W >= 0, got '" +
                  item + "'");
    *weight = w;
  }
  if (a.refit_asked() && a.no_refit)
    throw Error("--no-refit cannot be combined with --refit, --refit-rounds or --refit-sample");
  if (a.refit_asked()) {
    opt.refit_rounds = a.refit_rounds > 0 ? a.refit_rounds : RefitOptions{}.rounds;
    opt.refit_points_per_vertex = a.refit_sample;
  } else if (!a.no_refit && opt.placement == Placement::Optimal) {
    opt.refit_rounds = kDefaultRefitRounds;
    opt.refit_points_per_vertex = kDefaultRefitSample;
  }
  return opt;
}

LoadOptions to_load_options(const AlgorithmArgs& a) {
  LoadOptions load;
  if (a.weld) load.weld = Weld::On;
  if (a.no_weld) load.weld = Weld::Off;
  return load;
}

}  // namespace qem::cli
