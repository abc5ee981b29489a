// qem::simplify on the bumpy icospheres of bench_meshes.h (81,920 / 327,680 / 1,310,720 faces) to
// 10 % and 1 % of the faces: the same sizes and targets as the peer harness's sphere_1m3 runs, so
// `items_per_second` (input faces per second) can be set beside the peers' simplify_s.
// Only the simplify() call is timed; the mesh is built once per level, outside the loop.
#include <benchmark/benchmark.h>

#include <cstddef>

#include "bench_meshes.h"
#include "qem/simplify.h"

namespace {

// Args: {icosphere level, target in per mille of the input faces}.
void run_simplify(benchmark::State& state, const qem::SimplifyOptions& base) {
  const qem::Mesh& mesh = qem::bench::bumpy_icosphere(int(state.range(0)));
  qem::SimplifyOptions options = base;
  options.target_faces = mesh.face_count() * std::size_t(state.range(1)) / 1000;
  std::size_t out_faces = 0;
  double max_error_rel = 0;
  for (auto _ : state) {
    qem::SimplifyResult r = qem::simplify(mesh, options);
    out_faces = r.mesh.face_count();
    max_error_rel = r.max_error_relative;
    benchmark::DoNotOptimize(r.mesh.indices.data());
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(mesh.face_count()));
  state.counters["in_faces"] = double(mesh.face_count());
  state.counters["out_faces"] = double(out_faces);
  state.counters["max_err_rel"] = max_error_rel;
}

void BM_Simplify(benchmark::State& state) { run_simplify(state, {}); }

// The strict greedy order (GH97's heap) against the default pass-based order: the gap is what the
// passes save (the two orders' errors are compared in docs/benchmarks.md).
void BM_SimplifyGreedy(benchmark::State& state) {
  qem::SimplifyOptions o;
  o.scheme = qem::Scheme::Greedy;
  run_simplify(state, o);
}

// GH97's original settings (uniform plane weights, §5) against the default area weighting (HG99 §2):
// the cost of the quadric set-up itself is the same, so this shows any difference in the queue work.
void BM_SimplifyUniform(benchmark::State& state) {
  qem::SimplifyOptions o;
  o.weighting = qem::Weighting::Uniform;
  run_simplify(state, o);
}

// Fixed placement (GH97 Fig. 6) skips the 3x3 solve per candidate pair: the gap to BM_Simplify is
// the price of optimal placement.
void BM_SimplifyEndpoints(benchmark::State& state) {
  qem::SimplifyOptions o;
  o.placement = qem::Placement::Endpoints;
  run_simplify(state, o);
}

void sizes(benchmark::internal::Benchmark* b) {
  for (int level : {6, 7, 8})
    for (int permille : {100, 10}) b->Args({level, permille});
  b->ArgNames({"level", "permille"})->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();
}

}  // namespace

BENCHMARK(BM_Simplify)->Apply(sizes);
BENCHMARK(BM_SimplifyGreedy)->Apply(sizes);
BENCHMARK(BM_SimplifyUniform)
    ->Args({7, 10})
    ->ArgNames({"level", "permille"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
BENCHMARK(BM_SimplifyEndpoints)
    ->Args({7, 10})
    ->ArgNames({"level", "permille"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
