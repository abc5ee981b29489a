// qem::mesh_info (edges, borders, loops, Euler characteristic, components) on a bumpy icosphere:
// `qem info` runs it on every input, so it must stay a small fraction of a load.
#include <benchmark/benchmark.h>

#include "bench_meshes.h"
#include "qem/mesh_info.h"

namespace {

// Arg: icosphere level (8: 1.3M faces).
void BM_MeshInfo(benchmark::State& state) {
  const qem::Mesh& mesh = qem::bench::bumpy_icosphere(int(state.range(0)));
  for (auto _ : state) {
    qem::MeshInfo info = qem::mesh_info(mesh);
    benchmark::DoNotOptimize(info.edges);
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(mesh.face_count()));
}

}  // namespace

BENCHMARK(BM_MeshInfo)->Arg(6)->Arg(8)->Unit(benchmark::kMillisecond)->UseRealTime();
