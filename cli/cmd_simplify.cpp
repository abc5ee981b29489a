// `qem simplify INPUT OUTPUT [options]`: GH97 simplification of a mesh file.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>

#include "algorithm_options.h"
#include "cli_util.h"
#include "command.h"
#include "out_of_core_cli.h"
#include "partition/partition_targets.h"
#include "partition_cli.h"
#include "qem/error.h"
#include "qem/gltf.h"
#include "qem/gltf_simplify.h"
#include "qem/io.h"
#include "qem/progressive.h"
#include "qem/simplify.h"

namespace qem::cli {
namespace {

struct SimplifyArgs {
  std::string input, output;
  std::optional<std::size_t> faces, vertices;  // given as 0: as far as the checks allow
  std::optional<double> ratio;
  double max_error = -1, max_error_rel = -1;
  double max_distance = -1, max_distance_rel = -1;
  AlgorithmArgs algorithm;
  bool ascii = false, json = false, quiet = false, force = false;
  bool double_values = false;  // --double
  bool per_mesh = false;       // --per-mesh (glTF documents)
  std::string record;          // --record: the contraction sequence (docs/record-format.md)
  OutOfCoreArgs out_of_core;   // --memory-limit, --temp-dir
  PartitionArgs partition;     // --partition
};

// Shows the progress on a terminal and, with --record, keeps the contractions.
class Watcher : public ContractionRecorder {
 public:
  Watcher(bool show_progress, bool record) : show_progress_(show_progress), record_(record) {}
  bool wants_contractions() const override { return record_; }
  // Without --record the input's faces are not kept (the recorder copies and sorts them).
  void on_start(std::span<const std::uint32_t> input_faces) override {
    if (record_) ContractionRecorder::on_start(input_faces);
  }
  bool on_progress(double fraction) override {
    if (show_progress_) {
      std::fprintf(stderr, "\rqem: simplifying %5.1f%%", 100 * fraction);
      std::fflush(stderr);
    }
    return true;
  }

 private:
  bool show_progress_, record_;
};

/// glTF in and out: the document is kept (qem/gltf_simplify.h) and only its primitives change.
int run_simplify_gltf(const SimplifyArgs& a, const SimplifyOptions& opt) {
  Stopwatch total;
  Stopwatch t_load;
  GltfDocument doc = GltfDocument::load(a.input);
  const double load_s = t_load.seconds();
  Stopwatch t_simplify;
  const double cpu0 = process_cpu_seconds();
  GltfSimplifyOptions gltf_options;
  gltf_options.per_primitive = a.per_mesh;
  gltf_options.threads = a.algorithm.threads;
  const GltfSimplifyReport r = simplify_document(doc, opt, gltf_options);
  const double simplify_s = t_simplify.seconds();
  const double simplify_cpu_s = process_cpu_seconds() - cpu0;
  Stopwatch t_write;
  doc.save(a.output);
  const double write_s = t_write.seconds();
  // What was kept or dropped (primitives not of triangles, TANGENT...): about the input, so not
  // silenced by --quiet, like the readers' warnings.
  for (const std::string& n : doc.notes()) std::fprintf(stderr, "qem: note: %s\n", n.c_str());
  std::size_t out_vertices = 0;
  for (const GltfPrimitiveInfo& p : doc.primitives()) out_vertices += p.vertex_count;
  // Primitives that ran out of allowed contractions (locked borders, topology, inversion): before
  // their target, so that the scene's target may be missed, which the summary says; or, asked to go
  // as far as the checks allow (a target of 0), where they were asked to stop.
  std::size_t at_dead_end = 0;
  for (const GltfPrimitiveOutcome& o : r.primitives)
    at_dead_end +=
        o.status == GltfPrimitiveOutcome::Status::Simplified && o.stop_reason == StopReason::NoValidPair;
  const std::size_t stopped_early = opt.as_far_as_possible ? 0 : at_dead_end;
  if (a.json) {
    // Each primitive: where it is in the document, what happened to it, its error in world units.
    std::string each;
    for (const GltfPrimitiveOutcome& o : r.primitives) {
      const GltfPrimitiveInfo& p = doc.primitives()[o.primitive];
      const char* status = to_string(o.status);
      each += std::string(each.empty() ? "" : ",") + "{\"mesh\":" + std::to_string(p.mesh) +
              ",\"primitive\":" + std::to_string(p.primitive) + ",\"status\":\"" + status +
              "\",\"in_faces\":" + std::to_string(o.faces_in) +
              ",\"out_faces\":" + std::to_string(o.faces_out) +
              ",\"world_scale\":" + json_number(o.world_scale) +
              ",\"world_error\":" + json_number(o.world_error) + ",\"stop\":\"" +
              (o.status == GltfPrimitiveOutcome::Status::Simplified ? to_string(o.stop_reason) : "") + "\"}";
    }
    std::printf(
        "{\"tool\":\"qem\",\"format\":\"gltf\",\"per_mesh\":%s,\"primitives\":%zu,\"simplified\":%zu,"
        "\"unchanged\":%zu,\"kept\":%zu,\"stopped_early\":%zu,\"in_faces\":%zu,\"target_faces\":%zu,"
        "\"out_faces\":%zu,"
        "\"out_vertices\":%zu,\"max_error\":%s,\"output_to_input_distance\":%s,\"world_threshold\":%s,"
        "\"load_s\":%s,\"simplify_s\":%s,"
        "\"simplify_cpu_s\":%s,\"write_s\":%s,\"total_s\":%s,\"peak_rss_mb\":%s,\"each\":[%s]}\n",
        a.per_mesh ? "true" : "false", r.primitives.size(), r.simplified, r.unchanged, r.kept, stopped_early,
        r.faces_in, r.target_faces, r.faces_out, out_vertices, json_number(r.max_world_error).c_str(),
        json_number(r.max_world_distance).c_str(), json_number(r.world_threshold).c_str(), json_number(load_s).c_str(), json_number(simplify_s).c_str(),
        json_number(simplify_cpu_s).c_str(), json_number(write_s).c_str(),
        json_number(total.seconds()).c_str(), json_number(peak_rss_mb()).c_str(), each.c_str());
  }
  if (!a.quiet)
    std::fprintf(stderr,
                 "qem: %zu -> %zu faces in %zu primitives (%zu simplified, %zu needed no change, %zu kept as "
                 "they were), max error %.4g in world units, %.3f s; the rest of the document is unchanged\n",
                 r.faces_in, r.faces_out, r.primitives.size(), r.simplified, r.unchanged, r.kept,
                 r.max_world_error, total.seconds());
  if (!a.quiet && std::isfinite(opt.max_distance))
    std::fprintf(stderr, "qem: distance from the output to the input %.4g in world units (sampled; bound %.4g%s)\n",
                 r.max_world_distance, opt.max_distance,
                 !opt.max_distance_is_relative ? " in world units"
                 : a.per_mesh                  ? " of each primitive's diagonal"
                                               : " of the scene's diagonal");
  if (!a.quiet && at_dead_end > 0)
    std::fprintf(stderr,
                 "qem: %zu primitive%s %s: no contraction left that keeps the topology, the borders and "
                 "the face orientations\n",
                 at_dead_end, at_dead_end == 1 ? "" : "s",
                 stopped_early == 0 ? "went as far as the checks allow"
                 : a.per_mesh       ? "stopped before its target"
                                    : "stopped before the scene's target");
  return 0;
}

int run_simplify(const SimplifyArgs& a) {
  refuse_to_overwrite(a.input, a.output, a.force);
  SimplifyOptions opt = to_simplify_options(a.algorithm);
  const bool gltf_document = format_from_extension(a.input) == FileFormat::Gltf &&
                             format_from_extension(a.output) == FileFormat::Gltf;
  if (a.per_mesh && !gltf_document)
    throw Error(
        "--per-mesh applies to glTF documents (.glb / .gltf in and out): other formats hold one mesh");
  if (gltf_document && !a.record.empty())
    throw Error(
        "--record keeps one mesh's contractions, and a glTF document is simplified primitive by "
        "primitive: simplify without --record, or write a single mesh (e.g. .ply) to record it");
  // A record replays the contractions, and a refit moves every vertex after them, so `qem replay`
  // could not give back what simplify wrote: with --record there is no refit (not the default's).
  if (!a.record.empty() && a.algorithm.refit_asked())
    throw Error(
        "--record cannot be combined with --refit: a record replays the contractions, and the refit "
        "moves every vertex after them, so `qem replay` could not give back what simplify wrote; "
        "use `qem lod --refit`, or `qem refit` on a replayed level");
  // Nor the repair of the far places (it too comes after the contractions).
  if (!a.record.empty()) opt.refit_rounds = 0, opt.far_repair = false;
  opt.target_faces = a.faces.value_or(0);
  opt.target_ratio = a.ratio.value_or(0);
  opt.target_vertices = a.vertices.value_or(0);
  opt.as_far_as_possible = a.faces == 0u || a.ratio == 0.0 || a.vertices == 0u;
  if (a.max_error >= 0) opt.max_error = a.max_error;
  if (a.max_error_rel >= 0) opt.max_error = a.max_error_rel, opt.max_error_is_relative = true;
  if (a.max_distance >= 0) opt.max_distance = a.max_distance;
  if (a.max_distance_rel >= 0) opt.max_distance = a.max_distance_rel, opt.max_distance_is_relative = true;
  check_options(opt);  // before the input is read: a slip in the options is said at once
  // A document's primitives carry attributes (NORMAL, TEXCOORD_n...) as a rule: the default's light
  // refit is left out for them as for any mesh with attributes; --refit asks for it.
  if (gltf_document) {
    opt.refit_rounds = attribute_refit_rounds(a.algorithm, opt);
    opt.far_repair = far_repair_wanted(a.algorithm, opt);
    return run_simplify_gltf(a, opt);
  }
  // An input too large for memory goes the out-of-core way (qem/out_of_core.h); others as before.
  if (a.record.empty() && wants_out_of_core(a.input, a.out_of_core)) {
    OutOfCoreArgs ooc = a.out_of_core;
    ooc.partition = a.partition.partition;
    return run_out_of_core(a.input, a.output, opt, ooc,
                           {a.ascii, a.json, a.quiet, a.double_values, a.faces.value_or(0)});
  }

  const bool show_progress = !a.quiet && !a.json && ::isatty(STDERR_FILENO);

  Stopwatch total;
  LoadOptions load = to_load_options(a.algorithm);
  LoadReport report;
  Stopwatch t_load;
  Mesh mesh = load_input(a.input, load, &report);
  std::vector<std::uint8_t> lock;  // --lock-property: outlives the run, as vertex_lock must
  apply_lock_property(a.algorithm, a.input, mesh, lock, opt);
  if (!mesh.attributes.empty()) {
    opt.refit_rounds = attribute_refit_rounds(a.algorithm, opt, mesh);
    opt.far_repair = far_repair_wanted(a.algorithm, opt);
  }
  const double load_s = t_load.seconds();
  if (!a.record.empty() && (!mesh.attributes.empty() || !mesh.face_materials.empty()))
    throw Error(a.input + ": --record keeps positions and faces only, and this mesh has " +
                (mesh.attributes.empty() ? std::string("face materials")
                                         : "attributes (" + mesh.attributes.front().name + ", ...)") +
                " that a replay would lose; simplify without --record, or " +
                "use `qem lod`, which makes each level with its attributes and materials");

  Stopwatch t_simplify;
  const double cpu0 = process_cpu_seconds();
  Watcher watcher(show_progress, !a.record.empty());
  const std::size_t in_faces = mesh.face_count();
  const unsigned asked_parts = choose_parts(a.partition, mesh, opt, !a.record.empty());
  PartitionReport partition_report;
  // Without a record the input's faces are not needed afterwards: let the simplifier free them.
  SimplifyResult r = asked_parts > 1      ? run_partitioned(mesh, opt, asked_parts, show_progress, &partition_report)
                     : a.record.empty() ? simplify(std::move(mesh), opt, &watcher)
                                        : simplify(mesh, opt, &watcher);
  // A partitioned run may have run whole (a two-sided sheet's duplicates: qem/partition.h).
  const unsigned parts = asked_parts > 1 ? partition_report.parts : 1;
  if (asked_parts > 1 && parts == 1 && !a.quiet)
    std::fprintf(stderr, "qem: duplicate faces (two-sided sheets: --two-sided) need the whole mesh in one run, "
                         "made instead of the parts\n");
  // The partitioned run reads a view of the mesh, which has no material names: they stay the input's.
  if (asked_parts > 1) r.mesh.material_names = mesh.material_names, r.mesh.material_library = mesh.material_library;
  const double simplify_s = t_simplify.seconds();
  const double simplify_cpu_s = process_cpu_seconds() - cpu0;
  if (show_progress && asked_parts <= 1) std::fprintf(stderr, "\n");

  Stopwatch t_write;
  SaveOptions save;
  save.binary = !a.ascii;
  save.double_precision = a.double_values || report.double_precision;
  save_mesh(a.output, r.mesh, save);
  if (!a.record.empty()) {  // written atomically, like the mesh
    Record record = make_record(mesh, watcher.log);
    record.double_input = report.double_precision;  // so that replay writes what simplify wrote
    write_record(a.record, record);
  }
  const double write_s = t_write.seconds();

  if (a.json) {
    std::printf(
        // clang-format off (one group of fields a line, no name split)
        "{\"tool\":\"qem\",\"in_faces\":%zu,\"target_faces\":%zu,\"out_faces\":%zu,\"out_vertices\":%zu,"
        "\"load_s\":%s,\"simplify_s\":%s,\"simplify_cpu_s\":%s,\"write_s\":%s,\"total_s\":%s,"
        "\"peak_rss_mb\":%s,\"max_error\":%s,\"max_error_rel\":%s,\"contractions\":%zu,\"virtual_pairs\":%zu,"
        "\"rejected_topology\":%zu,\"rejected_inversion\":%zu,\"rejected_error\":%zu,"
        "\"rejected_component\":%zu,"
        "\"rejected_distance\":%zu,\"output_to_input_distance\":%s,"
        "\"in_components\":%zu,\"out_components\":%zu,\"pruned_components\":%zu,\"refit_rounds\":%zu,"
        "\"refit_rms_before\":%s,\"refit_rms_after\":%s,\"edge_flips\":%zu,\"vertex_moves\":%zu,"
        "\"vertex_relocations\":%zu,\"dropped_degenerate\":%zu,\"dropped_duplicate\":%zu,\"twin_faces\":%zu,"
        "\"parts\":%u,\"split_s\":%s,\"parts_s\":%s,\"final_pass_s\":%s,\"parts_cpu_s\":%s,"
        "\"busiest_thread_cpu_s\":%s,\"normal_weight\":%s,\"color_weight\":%s,\"stop\":\"%s\"}\n",
        // clang-format on
        in_faces, partition_detail::resolve_targets(opt, in_faces).faces, r.mesh.face_count(),
        r.mesh.vertex_count(), json_number(load_s).c_str(), json_number(simplify_s).c_str(),
        json_number(simplify_cpu_s).c_str(), json_number(write_s).c_str(),
        json_number(total.seconds()).c_str(), json_number(peak_rss_mb()).c_str(),
        json_number(r.max_error).c_str(), json_number(r.max_error_relative).c_str(), r.contractions,
        r.virtual_pairs, r.rejected_topology, r.rejected_inversion, r.rejected_error, r.rejected_component,
        r.rejected_distance, json_number(r.output_to_input_distance).c_str(), r.input_components,
        r.output_components, r.pruned_components, r.refit_rounds, json_number(r.refit_rms_before).c_str(),
        json_number(r.refit_rms_after).c_str(), r.edge_flips, r.vertex_moves, r.vertex_relocations,
        r.dropped_degenerate_faces, r.dropped_duplicate_faces, r.twin_faces, parts,
        json_number(partition_report.split_seconds).c_str(),
        json_number(partition_report.parts_seconds).c_str(),
        json_number(partition_report.final_seconds).c_str(),
        json_number(partition_report.parts_cpu_seconds).c_str(),
        json_number(partition_report.busiest_thread_cpu_seconds).c_str(),
        json_number(r.normal_weight).c_str(), json_number(r.color_weight).c_str(), to_string(r.stop_reason));
  }
  if (!a.quiet)
    std::fprintf(stderr,
                 "qem: %zu -> %zu faces, %zu vertices, %zu -> %zu components%s, max error %.4g (%.3g of diagonal), "
                 "%.3f s; %s\n",
                 r.input_faces, r.mesh.face_count(), r.mesh.vertex_count(), r.input_components, r.output_components,
                 r.pruned_components > 0 ? (" (" + std::to_string(r.pruned_components) + " pruned)").c_str() : "",
                 r.max_error, r.max_error_relative, total.seconds(), r.stop_detail.c_str());
  if (!a.quiet && parts > 1)
    std::fprintf(stderr,
                 "qem: in %u parts (%zu vertices on the cuts, locked in the parts: %.3f s), then one pass over "
                 "the %zu welded faces (%.3f s)\n",
                 parts, partition_report.shared_vertices, partition_report.parts_seconds, partition_report.merged_faces,
                 partition_report.final_seconds);
  if (!a.quiet && r.dropped_degenerate_faces + r.dropped_duplicate_faces > 0)
    std::fprintf(stderr, "qem: left out %zu degenerate and %zu duplicate input faces\n",
                 r.dropped_degenerate_faces, r.dropped_duplicate_faces);
  if (!a.quiet && r.twin_faces > 0)
    std::fprintf(stderr, "qem: put back the reversed twins of %zu faces of two-sided sheets (--two-sided %s)\n",
                 r.twin_faces, a.algorithm.two_sided.c_str());
  if (!a.quiet && std::isfinite(opt.max_distance)) {
    // The bound as the user gave it: a relative bound is compared with the distance over the diagonal.
    char relative[64] = "";
    if (opt.max_distance_is_relative)
      std::snprintf(relative, sizeof relative, ", %.4g of the diagonal", r.output_to_input_distance_relative);
    std::fprintf(stderr,
                 "qem: distance from the output to the input %.4g%s (sampled; bound %.4g%s), %zu contractions "
                 "refused for it\n",
                 r.output_to_input_distance, relative, opt.max_distance,
                 opt.max_distance_is_relative ? " of the diagonal" : "", r.rejected_distance);
  }
  if (!a.quiet && opt.refit_rounds > 0)
    std::fprintf(stderr, "qem: refit in %zu round%s: RMS distance of the input's vertices %.4g -> %.4g\n",
                 r.refit_rounds, r.refit_rounds == 1 ? "" : "s", r.refit_rms_before, r.refit_rms_after);
  return 0;
}

const bool registered = register_command(10, [](CLI::App& app) {
  auto args = std::make_shared<SimplifyArgs>();
  CLI::App* sub = app.add_subcommand("simplify", "Simplify a mesh by quadric-error pair contraction (GH97)");
  sub->add_option("input", args->input, "Input mesh (.obj .ply .stl .off .glb .gltf)")->required();
  sub->add_option("output", args->output,
                  "Output mesh; format by extension (.obj .ply .stl .off .glb .gltf). glTF to glTF keeps the "
                  "document: every triangle primitive is simplified with its attributes, and materials, "
                  "textures, nodes, skins, animations and extensions pass through; the target is the "
                  "scene's, every primitive stopping at about the same error in world units (--per-mesh: "
                  "each primitive's). glTF to another format writes the scene merged into one mesh")
      ->required();
  auto* g = sub->add_option_group("target", "Stop criteria (any combination; the first reached wins)");
  g->add_option("--faces,-f", args->faces,
                "Stop at or below this many faces; 0 = as far as the checks allow (topology, inversion, "
                "components, --max-error, locks)");
  g->add_option("--ratio,-r", args->ratio,
                "Stop at or below this fraction of the input faces, in [0, 1]; 0 = as far as the checks allow");
  g->add_option("--vertices", args->vertices, "Stop at or below this many vertices; 0 = as far as the checks allow");
  g->add_option("--max-error", args->max_error,
                "Never make a contraction whose error exceeds this distance (model units; world units for a glTF document): the error is "
                "sqrt(Q(v)/weight), the weighted RMS distance of the new vertex to the planes it represents; "
                "0 = only contractions without error (flat, straight parts)");
  g->add_option("--max-error-rel", args->max_error_rel,
                "As --max-error, relative to the bounding-box diagonal; 0 = only contractions without error");
  g->add_option("--max-distance", args->max_distance,
                "No output point farther than this from the input surface (model units): each contraction's "
                "new faces are certified against the input (adaptive subdivision, conservative) "
                "and refused otherwise; the refit keeps it too. Alone: as few faces as the bound allows")
      ->check(CLI::PositiveNumber);
  g->add_option("--max-distance-rel", args->max_distance_rel, "As --max-distance, relative to the bounding-box diagonal")
      ->check(CLI::PositiveNumber);
  add_algorithm_options(sub, args->algorithm);
  sub->add_flag("--ascii", args->ascii, "Write PLY / STL as text instead of binary");
  sub->add_flag("--double", args->double_values, kDoubleOutputHelp);
  sub->add_flag("--json", args->json,
                "Print one JSON line with counts, timings, memory and error on stdout (glTF documents: also "
                "\"each\", one entry per primitive)");
  sub->add_flag("--quiet,-q", args->quiet, "No progress and no summary on stderr");
  sub->add_flag("--per-mesh", args->per_mesh,
                "glTF: apply the target to each primitive on its own (--ratio 0.5 halves every one) "
                "instead of sharing one error budget across the scene");
  sub->add_flag("--force", args->force, "Allow the output to overwrite the input file");
  sub->add_option(
      "--record", args->record,
      "Also write the contraction sequence to this file, so `qem replay` / `qem lod` can rebuild "
      "any face count between the output's and the input's (docs/record-format.md); no default refit then");
  add_out_of_core_options(sub, args->out_of_core);
  add_partition_option(sub, args->partition);
  return [args] { return run_simplify(*args); };
});

}  // namespace
}  // namespace qem::cli
