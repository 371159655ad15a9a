// Loading speed: parse, repair, quality figures. Real meshes from ../shared/data when present,
// else the bundled bunny only. Results go to docs/benchmarks.md with the machine.
#include <filesystem>
#include <string>

#include <benchmark/benchmark.h>

#include "remora/geometry/quality.h"
#include "remora/mesh/io.h"

namespace {

std::string shared(const std::string& rel) {
  return std::string(REMORA_SHARED_DATA) + "/" + rel;
}

void read_soup_bench(benchmark::State& state, const std::string& path) {
  if (!std::filesystem::exists(path)) {
    state.SkipWithError(("missing " + path).c_str());
    return;
  }
  std::size_t faces = 0;
  for (auto _ : state) {
    remora::SoupFile f = remora::read_soup(path);
    faces = f.soup.num_polygons();
    benchmark::DoNotOptimize(f);
  }
  state.counters["faces"] = static_cast<double>(faces);
}

void read_mesh_bench(benchmark::State& state, const std::string& path) {
  if (!std::filesystem::exists(path)) {
    state.SkipWithError(("missing " + path).c_str());
    return;
  }
  std::size_t faces = 0;
  for (auto _ : state) {
    remora::LoadResult r = remora::read_mesh(path);
    faces = r.mesh.n_faces();
    benchmark::DoNotOptimize(r);
  }
  state.counters["faces"] = static_cast<double>(faces);
}

void quality_bench(benchmark::State& state, const std::string& path) {
  if (!std::filesystem::exists(path)) {
    state.SkipWithError(("missing " + path).c_str());
    return;
  }
  const remora::LoadResult r = remora::read_mesh(path);
  for (auto _ : state) benchmark::DoNotOptimize(remora::mesh_quality(r.mesh));
  state.counters["faces"] = static_cast<double>(r.mesh.n_faces());
}

const std::string kBunny = std::string(REMORA_REPO_DATA) + "/bunny.ply";

BENCHMARK_CAPTURE(read_soup_bench, bunny_ascii_ply, kBunny)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_mesh_bench, bunny_ascii_ply, kBunny)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_mesh_bench, conrod_stl, shared("cad/conrod.stl"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_mesh_bench, armadillo_obj, shared("scans/armadillo.obj"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_soup_bench, igea_tristrips, shared("scans/igea.ply"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_mesh_bench, igea_tristrips, shared("scans/igea.ply"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_soup_bench, igea_sub4_binary_ply, shared("derived/igea_sub4.ply"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_mesh_bench, igea_sub4_binary_ply, shared("derived/igea_sub4.ply"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(quality_bench, bunny, kBunny)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(quality_bench, igea_sub4, shared("derived/igea_sub4.ply"))
    ->Unit(benchmark::kMillisecond);

} // namespace
