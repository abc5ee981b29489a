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
  sub->add_option(
         "--forget", a.forget,
         "Renew every quadric from the current faces each time the faces fall by this factor (0 = never, "
         "GH97's quadrics; off with --max-error, and with attributes that vary unless --forget-attributes)")
      ->check(CLI::Range(0.0, 0.999999))
      ->capture_default_str();
  sub->add_flag("--forget-attributes", a.forget_attributes,
                "With attributes, forget too: renew the wedges' attribute quadrics and the seam planes with the "
                "positions' (lower geometric error on most assets; attribute errors may rise on some)");
  sub->add_option("--threads", a.threads, "Threads for the passes: re-costing pairs, and making contractions region by region (0 = all; same result)")
      ->capture_default_str();
  sub->add_option("--boundary-weight", a.boundary_weight,
                  "Weight of GH97 6's boundary constraint planes, times the squared edge length (0 = off). "
                  "Given alone it asks for GH97's penalty borders (as --penalty-borders, with this weight); "
                  "with --exact-borders the planes only rank the contractions")
      ->each([&a](const std::string&) { a.boundary_weight_given = true; })
      ->capture_default_str();
  sub->add_flag("--exact-borders", a.exact_borders,
                "The default: border vertices stay on the input's border polylines (they may slide along "
                "them); border ends and junctions are kept exactly, and corners (turns above 45 degrees) "
                "too until the run's error reaches their distance from the border that would replace "
                "them, so tiles and CAD patches still meet (docs/benchmarks.md, Borders)");
  sub->add_flag("--penalty-borders", a.penalty_borders,
                "GH97 6's penalty instead of exact borders: the boundary planes (--boundary-weight) pull "
                "the placement and border vertices may leave the border by a little");
  sub->add_flag("--lock-border", a.lock_border, "Boundary vertices never move (nor are removed)");
  sub->add_option(
         "--attribute-weight", a.attribute_weights,
         "Weight of an attribute's error against distance, as KIND=W (normal, uv, color, scalar; "
         "repeat or separate by commas): a difference of 1/W costs as much as one bounding-box "
         "diagonal (defaults: normal=" +
             json_number(AttributeWeights{}.normal) + ", uv=" + json_number(AttributeWeights{}.tex_coord) +
             ", color=" + json_number(AttributeWeights{}.color) +
             ", scalar=" + json_number(AttributeWeights{}.scalar) +
             "); seam=W weighs constraint planes along "
             "the seams, as --boundary-weight for borders (default " +
             json_number(AttributeWeights{}.seam) +
             "); normal-spacing=K: by default the normal weight is at least K (" +
             json_number(AttributeWeights{}.normal_per_spacing) +
             ") times the spacing of the target's faces, sqrt(area / faces) in diagonals, so that coarse "
             "outputs keep small sharply turning parts; color-spacing=K: the colour weight at least K (" +
             json_number(AttributeWeights{}.color_per_spacing) + ") times that spacing, up to " +
             json_number(AttributeWeights{}.color_spacing_cap) +
             "; a normal or colour weight given alone is used as it is")
      ->delimiter(',');
  sub->add_option(
         "--seams", a.seams,
         "With attributes, seams (UV seams, normal creases, colour and material boundaries): junctions "
         "(a collapse runs only along a seam, both sides together, except that a vertex where three or "
         "more charts, creases or colours meet may merge into a neighbouring such vertex when its "
         "error, the attribute error included, allows: meshoptimizer's default), strict (as junctions, "
         "but those vertices never move), creases (as strict along UV seams and material boundaries, "
         "but a collapse may cross a normal crease or a colour boundary when its error allows; "
         "gltfpack's -sp), or permissive (UV seams may be crossed too: reaches targets that many small "
         "UV charts block, at some UV quality, and can smear a texture or lose a feature drawn in a "
         "small chart); docs/attributes.md")
      ->check(CLI::IsMember(option_names<SeamMode>()))
      ->capture_default_str();
  sub->add_option("--lock", a.lock,
                  "Vertices that never move and are never removed: seams (every position with more than "
                  "one set of attributes), borders (as --lock-border); separate by commas")
      ->check(CLI::IsMember({"seams", "borders"}))
      ->delimiter(',');
  sub->add_option("--lock-property", a.lock_property,
                  "Lock the vertices whose PLY vertex property (or scalar attribute) NAME is non-zero")
      ->type_name("NAME");
  sub->add_option("--inversion", a.inversion, "Contractions that flip a face (turn it past --max-turn, or make it face away from its input "
                  "face): forbid, penalize, or off (GH97 6)")
      ->check(CLI::IsMember(option_names<InversionPolicy>()))
      ->capture_default_str();
  sub->add_option("--max-turn", a.max_turn, "A face normal turning by more than this (degrees, < 90) is a flip")
      ->capture_default_str();
  sub->add_flag("--allow-non-manifold", a.allow_non_manifold,
                "Do not check the link condition: edge collapses may create non-manifold edges");
  sub->add_flag("--allow-vanishing", a.allow_vanishing,
                "GH97 as published: a connected part may contract to nothing. By default every part keeps at "
                "least one face, a closed one four (a tetrahedron); parts that --threshold joins count as one");
  sub->add_option("--prune", a.prune,
                  "Remove whole the connected parts whose bounding-box diagonal is below this distance (model "
                  "units) before simplifying; 0 = none")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--prune-rel", a.prune_rel, "As --prune, relative to the whole mesh's bounding-box diagonal")
      ->check(CLI::NonNegativeNumber);
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
                    ", fewer rounds or none where each output vertex stands for fewer than 6 or 3 input vertices) when --placement is optimal and the mesh has no texture coordinates or normals (with "
                    "those only when asked; it holds the seams; docs/attributes.md); see --no-refit");
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
  sub->add_flag("--far-repair", a.far_repair,
                "After the run and the refit, repair the places farthest from the input: flip an edge, "
                "move an interior vertex toward the input points far from it, or take a vertex from the "
                "flattest place to the farthest (a split there, a collapse here), where that lowers the "
                "local Hausdorff distance without raising the local error; borders stay on the input's, "
                "seams and locked vertices stay (docs/benchmarks.md, \"Far places\"). On by default with "
                "the refit; this turns it on without it");
  sub->add_flag("--no-far-repair", a.no_far_repair, "No repair of the far places after the run (see --far-repair)");
  sub->add_option("--two-sided", a.two_sided,
                  "Sheets made two-sided by a reversed copy of each face (the same three points turning the other "
                  "way): one side is simplified, and then the copies come back on the output faces along the "
                  "sheet's rims (rims: the rim stays closed as in the input, the back left to a two-sided "
                  "material), on every output face whose input face had one (all: both sides, for renderers "
                  "that cull back faces), or on none (none). Counted in the target (docs/attributes.md, "
                  "\"Two-sided sheets\")")
      ->check(CLI::IsMember(option_names<TwoSided>()))
      ->capture_default_str();
  sub->add_flag("--attribute-fit", a.attribute_fit,
                "With attributes, after the run fit each vertex's values (off the seams) by least squares to "
                "the input's attributes at the output's points closest to the input's faces, instead of "
                "keeping those of its last contraction: lower UV, normal and colour errors, same positions; "
                "costs time and memory (docs/attributes.md)");
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
  opt.forget = a.forget;
  opt.forget_attributes = a.forget_attributes;
  opt.threads = a.threads;
  opt.boundary_weight = a.boundary_weight;
  opt.max_normal_turn_degrees = a.max_turn;
  opt.lock_border = a.lock_border;
  if (a.exact_borders && a.penalty_borders) throw Error("give --exact-borders or --penalty-borders, not both");
  // --boundary-weight alone is a request for GH97's penalty (the weight of a penalty).
  opt.exact_border = a.exact_borders || !(a.penalty_borders || a.boundary_weight_given);
  opt.preserve_topology = !a.allow_non_manifold;
  opt.keep_components = !a.allow_vanishing;
  if (a.prune > 0 && a.prune_rel > 0) throw Error("give --prune or --prune-rel, not both");
  if (a.prune_rel > 0) opt.prune_size = a.prune_rel, opt.prune_size_is_relative = true;
  else opt.prune_size = a.prune;
  bool normal_spacing_given = false, color_spacing_given = false;
  for (const std::string& item : a.attribute_weights) {
    const std::size_t eq = item.find('=');
    const std::string kind = item.substr(0, eq);
    double* weight = kind == "normal"           ? &opt.attribute_weights.normal
                     : kind == "uv"             ? &opt.attribute_weights.tex_coord
                     : kind == "color"          ? &opt.attribute_weights.color
                     : kind == "scalar"         ? &opt.attribute_weights.scalar
                     : kind == "seam"           ? &opt.attribute_weights.seam
                     : kind == "normal-spacing" ? &opt.attribute_weights.normal_per_spacing
                     : kind == "color-spacing"  ? &opt.attribute_weights.color_per_spacing
                                                : nullptr;
    char* end = nullptr;
    const double w = eq == std::string::npos ? -1 : std::strtod(item.c_str() + eq + 1, &end);
    if (!weight || eq == std::string::npos || !end || *end != 0 || !(w >= 0) || !std::isfinite(w))
      throw Error(
          "--attribute-weight: expected KIND=W with KIND normal, uv, color, scalar, seam, normal-spacing or "
          "color-spacing "
          "and W >= 0, got '" + item + "'");
    *weight = w;
    // A normal or colour weight given is the weight (unless its spacing factor is given too, before
    // or after it).
    if (kind == "normal" && !normal_spacing_given) opt.attribute_weights.normal_per_spacing = 0;
    if (kind == "normal-spacing") normal_spacing_given = true;
    if (kind == "color" && !color_spacing_given) opt.attribute_weights.color_per_spacing = 0;
    if (kind == "color-spacing") color_spacing_given = true;
  }
  opt.seams = parsed<SeamMode>("--seams", a.seams);
  opt.fit_attributes = a.attribute_fit;
  for (const std::string& what : a.lock) {
    if (what == "seams") opt.lock_seams = true;
    else if (what == "borders") opt.lock_border = true;
    else throw Error("--lock: expected seams or borders, got '" + what + "'");
  }
  if (a.refit_asked() && a.no_refit)
    throw Error("--no-refit cannot be combined with --refit, --refit-rounds or --refit-sample");
  if (a.refit_asked()) {
    opt.refit_rounds = a.refit_rounds > 0 ? a.refit_rounds : RefitOptions{}.rounds;
    opt.refit_points_per_vertex = a.refit_sample;
  } else if (!a.no_refit && opt.placement == Placement::Optimal) {
    opt.refit_rounds = kDefaultRefitRounds;
    opt.refit_points_per_vertex = kDefaultRefitSample;
    opt.refit_by_reduction = true;
  }
  if (a.far_repair && a.no_far_repair) throw Error("--far-repair cannot be combined with --no-far-repair");
  opt.far_repair = far_repair_wanted(a, opt);
  opt.two_sided = parsed<TwoSided>("--two-sided", a.two_sided);
  return opt;
}

LoadOptions to_load_options(const AlgorithmArgs& a) {
  LoadOptions load;
  if (a.weld) load.weld = Weld::On;
  if (a.no_weld) load.weld = Weld::Off;
  if (!a.lock_property.empty()) load.keep_vertex_properties = true;
  return load;
}

// The repair finishes the refit's work (the far places its least-squares moves leave): on with it
// unless asked otherwise, and not where the refit is left out (meshes with UVs or normals). There
// its flips and moves keep the error of appearance where it samples it (the input's vertices and
// faces round each change), but not everywhere: asked for on issue 18's assets it lowered E in
// about a third of the rows and raised the UV or normal error of four by 1-5 %
// (docs/benchmarks.md, "Appearance attributes").
bool far_repair_wanted(const AlgorithmArgs& a, const SimplifyOptions& options) {
  return a.far_repair || (options.refit_rounds > 0 && !a.no_far_repair);
}

unsigned attribute_refit_rounds(const AlgorithmArgs& a, const SimplifyOptions& options, const Mesh& mesh) {
  const bool uv_or_normals = mesh.find_attribute(AttributeKind::TexCoord) || mesh.find_attribute(AttributeKind::Normal);
  return a.refit_asked() || !uv_or_normals ? options.refit_rounds : 0;
}

unsigned attribute_refit_rounds(const AlgorithmArgs& a, const SimplifyOptions& options) {
  return a.refit_asked() ? options.refit_rounds : 0;
}

void apply_lock_property(const AlgorithmArgs& a, const std::string& file, const Mesh& mesh,
                         std::vector<std::uint8_t>& lock, SimplifyOptions& options) {
  if (a.lock_property.empty()) return;
  const std::vector<double>* values = nullptr;
  std::string known;
  for (const VertexProperty& p : mesh.vertex_properties) {
    if (p.name == a.lock_property) values = &p.values;
    known += (known.empty() ? "" : ", ") + p.name;
  }
  for (const VertexAttribute& attr : mesh.attributes) {
    if (attr.kind != AttributeKind::Scalar || attr.components != 1) continue;
    if (!values && attr.name == a.lock_property) values = &attr.values;
    known += (known.empty() ? "" : ", ") + attr.name;
  }
  if (!values)
    throw Error(file + ": --lock-property: no vertex property or scalar attribute named '" + a.lock_property +
                "' (" + (known.empty() ? std::string("it has none") : "it has: " + known) + ")");
  lock.assign(mesh.vertex_count(), 0);
  for (std::size_t v = 0; v < lock.size() && v < values->size(); ++v) lock[v] = (*values)[v] != 0;
  options.vertex_lock = lock;
}

}  // namespace qem::cli
