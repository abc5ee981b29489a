// qem::refit (Hoppe et al. 1993 §4.2) on the output of qem::simplify for the bumpy icospheres of
// bench_meshes.h at 10 % and 1 %: the extra time `--refit` adds to a simplification. The
// simplification runs once per case, outside the loop; each iteration refits a fresh copy.
#include <benchmark/benchmark.h>

#include <cstddef>

#include "bench_meshes.h"
#include "qem/refit.h"
#include "qem/simplify.h"

namespace {

// Args: {icosphere level, target in per mille of the input faces}.
void BM_Refit(benchmark::State& state) {
  const qem::Mesh& mesh = qem::bench::bumpy_icosphere(int(state.range(0)));
  qem::SimplifyOptions options;
  options.target_faces = mesh.face_count() * std::size_t(state.range(1)) / 1000;
  const qem::Mesh approx = qem::simplify(mesh, options).mesh;
  qem::RefitResult r;
  for (auto _ : state) {
    state.PauseTiming();
    qem::Mesh fitted = approx;
    state.ResumeTiming();
    r = qem::refit(mesh, fitted);
    benchmark::DoNotOptimize(fitted.positions.data());
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(mesh.vertex_count()));
  state.counters["out_faces"] = double(approx.face_count());
  state.counters["rms_ratio"] = r.rms_before > 0 ? r.rms_after / r.rms_before : 1;
  state.counters["rounds"] = double(r.rounds);
}

}  // namespace

BENCHMARK(BM_Refit)
    ->ArgsProduct({{6, 7}, {100, 10}})
    ->ArgNames({"level", "permille"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
