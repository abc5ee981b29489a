// qem::measure (GH97 §6.1 E, Hausdorff) between a bumpy icosphere and its 1 % simplification, at the
// peer harness's default of 1e6 samples and at 1e5. The time to compare with is that of the
// harness's own CGAL metric on the same output (../shared/bench/README.md, "The metric").
#include <benchmark/benchmark.h>

#include <cstddef>
#include <map>
#include <utility>

#include "bench_meshes.h"
#include "qem/measure.h"
#include "qem/simplify.h"

namespace {

const qem::Mesh& simplified_1pct(int level) {
  static std::map<int, qem::Mesh> cache;
  auto it = cache.find(level);
  if (it != cache.end()) return it->second;
  const qem::Mesh& mesh = qem::bench::bumpy_icosphere(level);
  qem::SimplifyOptions o;
  o.target_faces = mesh.face_count() / 100;
  return cache.emplace(level, qem::simplify(mesh, o).mesh).first->second;
}

// Args: {icosphere level, samples, threads (0 = all)}.
void BM_Measure(benchmark::State& state) {
  const int level = int(state.range(0));
  const qem::Mesh& original = qem::bench::bumpy_icosphere(level);
  const qem::Mesh& approx = simplified_1pct(level);
  qem::MeasureOptions o;
  o.samples = std::size_t(state.range(1));
  o.threads = unsigned(state.range(2));
  double e_rel = 0, h_rel = 0;
  for (auto _ : state) {
    qem::MeasureResult r = qem::measure(original, approx, o);
    e_rel = r.E_rel;
    h_rel = r.hausdorff_rel;
    benchmark::DoNotOptimize(r.E);
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()) * state.range(1));
  state.counters["E_rel"] = e_rel;
  state.counters["H_rel"] = h_rel;
}

}  // namespace

BENCHMARK(BM_Measure)
    ->Args({6, 100000, 1})
    ->Args({6, 1000000, 1})
    ->Args({8, 1000000, 1})
    ->Args({8, 1000000, 0})
    ->ArgNames({"level", "samples", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
