// qem::simplify end to end on a small real scan, the Stanford bunny (69,451 faces, GH97's own test
// mesh), to 10 % and 1 % of its faces, with the command line's defaults (light refit included): on
// inputs this small the per-run costs (set-up passes, allocations, threads, the greedy tail, the
// refit's set-up) weigh as much as the contractions, unlike on the icospheres of simplify_bench.cpp.
// The mesh is read once from ../shared/data (skipped if absent); only the simplify() call is timed.
#include <benchmark/benchmark.h>

#include <cstddef>
#include <filesystem>
#include <string>

#include "qem/io.h"
#include "qem/simplify.h"

namespace {

const qem::Mesh* bunny() {
  static const qem::Mesh* mesh = [] () -> const qem::Mesh* {
    const std::string path = std::string(QEM_SHARED_DIR) + "/data/gh_bunny_zipper.ply";
    if (!std::filesystem::exists(path)) return nullptr;
    return new qem::Mesh(qem::load_mesh(path));
  }();
  return mesh;
}

// Arg: target in per mille of the input faces.
void BM_SimplifyBunny(benchmark::State& state) {
  const qem::Mesh* mesh = bunny();
  if (!mesh) {
    state.SkipWithError("no ../shared/data/gh_bunny_zipper.ply");
    return;
  }
  qem::SimplifyOptions options;
  options.target_faces = mesh->face_count() * std::size_t(state.range(0)) / 1000;
  options.refit_rounds = 1;  // the command line's default light refit
  options.refit_points_per_vertex = 2;
  std::size_t out_faces = 0;
  for (auto _ : state) {
    qem::SimplifyResult r = qem::simplify(*mesh, options);
    out_faces = r.mesh.face_count();
    benchmark::DoNotOptimize(r.mesh.indices.data());
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(mesh->face_count()));
  state.counters["out_faces"] = double(out_faces);
}

}  // namespace

BENCHMARK(BM_SimplifyBunny)
    ->Arg(100)
    ->Arg(10)
    ->ArgName("permille")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
