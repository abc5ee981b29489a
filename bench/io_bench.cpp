// Reading and writing binary PLY: the part of `qem simplify` that is not simplification. The peer
// harness reports it as load_s / write_s; these isolate the parser (parse_mesh, bytes already in
// memory) from the file system (load_mesh, save_mesh).
#include <benchmark/benchmark.h>

#include <fstream>
#include <iterator>
#include <string>

#include "bench_meshes.h"
#include "qem/io.h"

namespace {

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void set_counters(benchmark::State& state, const qem::Mesh& mesh, std::size_t bytes) {
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(mesh.face_count()));
  state.SetBytesProcessed(std::int64_t(state.iterations()) * std::int64_t(bytes));
  state.counters["faces"] = double(mesh.face_count());
}

// Arg: icosphere level.
void BM_LoadBinaryPly(benchmark::State& state) {
  const std::string& path = qem::bench::bumpy_icosphere_ply(int(state.range(0)));
  const std::size_t bytes = read_file(path).size();  // also warms the page cache
  std::size_t faces = 0;
  for (auto _ : state) {
    qem::Mesh m = qem::load_mesh(path);
    faces = m.face_count();
    benchmark::DoNotOptimize(m.positions.data());
  }
  if (faces != qem::bench::bumpy_icosphere(int(state.range(0))).face_count())
    state.SkipWithError("load_mesh returned a different face count");
  set_counters(state, qem::bench::bumpy_icosphere(int(state.range(0))), bytes);
}

void BM_ParseBinaryPly(benchmark::State& state) {
  const std::string bytes = read_file(qem::bench::bumpy_icosphere_ply(int(state.range(0))));
  for (auto _ : state) {
    qem::Mesh m = qem::parse_mesh(bytes, qem::FileFormat::Ply, "bench.ply");
    benchmark::DoNotOptimize(m.positions.data());
  }
  set_counters(state, qem::bench::bumpy_icosphere(int(state.range(0))), bytes.size());
}

void BM_SerializeBinaryPly(benchmark::State& state) {
  const qem::Mesh& mesh = qem::bench::bumpy_icosphere(int(state.range(0)));
  std::size_t bytes = 0;
  for (auto _ : state) {
    std::string s = qem::serialize_mesh(mesh, qem::FileFormat::Ply, true);
    bytes = s.size();
    benchmark::DoNotOptimize(s.data());
  }
  set_counters(state, mesh, bytes);
}

}  // namespace

BENCHMARK(BM_LoadBinaryPly)->Arg(6)->Arg(8)->ArgName("level")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ParseBinaryPly)->Arg(6)->Arg(8)->ArgName("level")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SerializeBinaryPly)
    ->Arg(6)
    ->Arg(8)
    ->ArgName("level")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
