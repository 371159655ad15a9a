// The `remora` command line tool, run as a user would: exit codes, one clear error line, JSON
// that parses and agrees with the library, files written only on success.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include "remora/geometry/quality.h"
#include "remora/mesh/io.h"
#include "remora/mesh/primitives.h"
#include "remora/remesh/remesh.h"

namespace remora {
namespace {

namespace fs = std::filesystem;

struct CliRun {
  int exit_code;
  std::string out;
  std::string err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

class Cli : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("remora_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  CliRun run(const std::string& args) {
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string cmd = std::string(REMORA_CLI) + " " + args + " >" + out.string() + " 2>" +
                            err.string() + " </dev/null";
    const int status = std::system(cmd.c_str());
    CliRun r{WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
    fs::remove(out);
    fs::remove(err);
    return r;
  }

  fs::path write_text(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }

  fs::path dir_;
};

TEST_F(Cli, InfoJsonAgreesWithTheLibrary) {
  const fs::path cube = dir_ / "cube.off";
  write_mesh(cube.string(), make_cube(3, 2.0));
  const CliRun r = run("info --json " + cube.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const MeshQuality q = mesh_quality(read_mesh(cube.string()).mesh);
  EXPECT_EQ(j, [&] {
    nlohmann::json e = to_json(q);
    e["load"] = to_json(read_mesh(cube.string()).report);
    return e;
  }());
  EXPECT_EQ(j["load"]["repair"]["faces_loaded"], 108);
}

TEST_F(Cli, InfoTableNamesTheFiguresAndTheRepair) {
  const CliRun r = run(std::string("info ") + REMORA_REPO_DATA + "/bunny.ply");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* key : {"1,113 unreferenced vertices dropped", "69,451 faces", "5 boundary loops",
                          "mixed Voronoi", "mean |theta-60|"})
    EXPECT_NE(r.out.find(key), std::string::npos) << key << "\n" << r.out;
}

TEST_F(Cli, BrokenFileIsOneLineNamingTheFileAndPlaceWithExitCode1) {
  const fs::path bad = write_text("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n");
  const CliRun r = run("info " + bad.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(r.out.empty());
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("bad.obj: line 3"), std::string::npos) << r.err;
}

TEST_F(Cli, MissingFileAndUnknownExtensionFailCleanly) {
  EXPECT_EQ(run("info " + (dir_ / "nothing.ply").string()).exit_code, 1);
  const fs::path txt = write_text("mesh.txt", "hello");
  const CliRun r = run("info " + txt.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("mesh.txt"), std::string::npos) << r.err;
}

TEST_F(Cli, UnknownFlagOrMissingArgumentIsAUsageError) {
  EXPECT_EQ(run("info --no-such-flag x.obj").exit_code, 2);
  EXPECT_EQ(run("convert x.obj").exit_code, 2); // no -o
  EXPECT_EQ(run("").exit_code, 2);              // no subcommand
}

// Without the page's files `remora serve` stops before listening and names the make target and
// script that exist.
TEST_F(Cli, ServeWithoutThePageSaysHowToBuildIt) {
  const CliRun r = run("serve --port 0 --web-root " + dir_.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("index.html missing"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("`make build`"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("scripts/build_web.sh " + dir_.string()), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("make web"), std::string::npos) << r.err;
}

// A mesh the server refuses ends `remora bench serve` with its error and exit code 1; the
// loopback server is stopped on the way out, not left running into a crash.
TEST_F(Cli, BenchServeStopsItsServerOnAnError) {
  const fs::path bad = write_text("bad.off", "OFF\n3 1 0\n0 0 0\n1 0 nan\n0 1 0\n3 0 1 2\n");
  const CliRun r = run("bench serve --requests 1 " + bad.string());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("bad.off: line 4: vertex 1 has a non-finite z coordinate"),
            std::string::npos)
      << r.err;
}

TEST_F(Cli, ConvertWritesEveryFormatAndReportsTheRepair) {
  const fs::path in = dir_ / "in.stl";
  write_mesh(in.string(), make_icosphere(2));
  for (const char* ext : {"obj", "off", "ply", "stl"}) {
    const fs::path out = dir_ / (std::string("out.") + ext);
    const CliRun r = run("convert " + in.string() + " -o " + out.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("coincident vertices welded"), std::string::npos) << r.out;
    const LoadResult back = read_mesh(out.string());
    EXPECT_EQ(back.mesh.n_faces(), 320u);
    EXPECT_EQ(back.mesh.n_vertices(), 162u);
  }
}

TEST_F(Cli, FailedConvertLeavesNoFile) {
  const fs::path in = dir_ / "in.off";
  write_mesh(in.string(), make_cube(1, 1.0));
  const CliRun unknown = run("convert " + in.string() + " -o " + (dir_ / "out.xyz").string());
  EXPECT_EQ(unknown.exit_code, 1);
  const CliRun missing_dir =
      run("convert " + in.string() + " -o " + (dir_ / "no" / "such" / "out.obj").string());
  EXPECT_EQ(missing_dir.exit_code, 1);
  const fs::path broken = write_text("broken.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n");
  const CliRun truncated = run("convert " + broken.string() + " -o " + (dir_ / "out.obj").string());
  EXPECT_EQ(truncated.exit_code, 1);
  for (const auto& entry : fs::directory_iterator(dir_))
    EXPECT_TRUE(entry.path().filename() == "in.off" || entry.path().filename() == "broken.off")
        << "left behind: " << entry.path();
}

TEST_F(Cli, RemeshWritesTheMeshAndAReportThatAgreesWithIt) {
  const fs::path in = dir_ / "sphere.off";
  write_mesh(in.string(), make_icosphere(3));
  const fs::path out = dir_ / "remeshed.obj";
  const CliRun r = run("remesh " + in.string() + " -o " + out.string() + " --length 0.2 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const LoadResult back = read_mesh(out.string());
  EXPECT_EQ(j["after_equalization"]["faces"], back.mesh.n_faces());
  EXPECT_EQ(j["target_length"], 0.2);
  EXPECT_GE(j["cycles"], RemeshOptions{}.cycles);
  EXPECT_LE(j["cycles"], RemeshOptions{}.max_cycles);
  EXPECT_EQ(j["distance_to_input"]["vertex_max"], 0.0);
  const CliRun table = run("remesh " + in.string() + " -o " + out.string() + " --report");
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_NE(table.out.find("Laplacian symmetry defect"), std::string::npos) << table.out;
  // --feature-angle keeps the cube's edges: 4 mesh edges each at n = 4.
  const fs::path cube = dir_ / "cube.off";
  write_mesh(cube.string(), make_cube(4, 1.0));
  const CliRun features = run("remesh " + cube.string() + " -o " + out.string() +
                              " --length 0.2 --feature-angle 45 --json");
  ASSERT_EQ(features.exit_code, 0) << features.err;
  EXPECT_EQ(nlohmann::json::parse(features.out)["feature_edges"], 48);
  EXPECT_LT(nlohmann::json::parse(features.out)["distance_to_input"]["centroid_max"], 1e-12);
  EXPECT_EQ(
      run("remesh " + cube.string() + " -o " + out.string() + " --feature-angle 180").exit_code, 2);
}

// --low-pass remeshes the editor's base surface: on a sphere with radial noise, the output's
// radii spread far less than the input's, and far less than without the flag.
TEST_F(Cli, RemeshLowPassRemeshesTheSmoothedSurface) {
  Mesh sphere = make_icosphere(4);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> noise(-0.03, 0.03);
  for (const VertexHandle v : sphere.vertices())
    sphere.set_point(v, sphere.point(v) * (1.0 + noise(rng)));
  const fs::path in = dir_ / "noisy.off";
  write_mesh(in.string(), sphere);
  auto radius_spread = [](const Mesh& m) {
    double sum = 0, sum2 = 0;
    for (const VertexHandle v : m.vertices()) {
      const double r = m.point(v).norm();
      sum += r;
      sum2 += r * r;
    }
    const double n = static_cast<double>(m.n_vertices()), mean = sum / n;
    return std::sqrt(std::max(0.0, sum2 / n - mean * mean)) / mean;
  };
  const fs::path plain = dir_ / "plain.obj", smooth = dir_ / "smooth.obj";
  ASSERT_EQ(run("remesh " + in.string() + " -o " + plain.string()).exit_code, 0);
  const CliRun r = run("remesh " + in.string() + " -o " + smooth.string() + " --low-pass 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const double input = radius_spread(sphere);
  const double without = radius_spread(read_mesh(plain.string()).mesh);
  const double with = radius_spread(read_mesh(smooth.string()).mesh);
  EXPECT_GT(without, 0.5 * input); // remeshing alone keeps the noise it projects onto
  EXPECT_LT(with, 0.25 * input) << "input " << input << ", without " << without;
  EXPECT_EQ(run("remesh " + in.string() + " -o " + smooth.string() + " --low-pass -1").exit_code,
            2);
}

// The filter's feature cap reaches the command line: on a torus whose tube is thinner than σ
// every vertex is capped by default, none with --low-pass-cap 0, and a negative cap is refused.
TEST_F(Cli, RemeshLowPassCapsThinParts) {
  const fs::path in = dir_ / "torus.off", out = dir_ / "torus_out.obj";
  write_mesh(in.string(), make_torus(120, 12, 2.0, 0.2));
  const std::string base = "remesh " + in.string() + " -o " + out.string() + " --low-pass 2 ";
  const CliRun capped = run(base + "--json");
  ASSERT_EQ(capped.exit_code, 0) << capped.err;
  const auto j = nlohmann::json::parse(capped.out);
  EXPECT_EQ(j["low_pass"]["sigma_capped_vertices"], 120 * 12);
  EXPECT_NEAR(j["low_pass"]["sigma_min"].get<double>(), 0.2, 0.002);
  const CliRun plain = run(base + "--low-pass-cap 0 --json");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_EQ(nlohmann::json::parse(plain.out)["low_pass"]["sigma_capped_vertices"], 0);
  EXPECT_EQ(run(base + "--low-pass-cap -1").exit_code, 2);
  // The cap without --low-pass would change nothing: a usage error, not a silent no-op.
  const CliRun alone = run("remesh " + in.string() + " -o " + out.string() + " --low-pass-cap 0.5");
  EXPECT_EQ(alone.exit_code, 2);
  EXPECT_NE(alone.err.find("--low-pass"), std::string::npos) << alone.err;
}

TEST_F(Cli, RemeshRejectsBadOptionsBeforeWorking) {
  const fs::path in = dir_ / "sphere.off";
  write_mesh(in.string(), make_icosphere(1));
  EXPECT_EQ(
      run("remesh " + in.string() + " -o " + (dir_ / "o.obj").string() + " --lambda 2").exit_code,
      2);
  EXPECT_EQ(run("remesh " + in.string() + " -o " + (dir_ / "o.obj").string() +
                " --length 1 --length-factor 2")
                .exit_code,
            2);
  EXPECT_EQ(run("remesh " + in.string() + " -o " + (dir_ / "o.xyz").string()).exit_code, 1);
  EXPECT_EQ(
      run("remesh " + in.string() + " -o " + (dir_ / "o.obj").string() + " --corner-angle 200")
          .exit_code,
      2);
  // Usage errors (2), not the library's refusal (1), at the ends the library excludes too.
  for (const char* option : {" --settle 2", " --max-cycles -1", " --smoothing-target median",
                             " --lambda 0", " --guard-angle 60", " --lambda x"})
    EXPECT_EQ(run("remesh " + in.string() + " -o " + (dir_ / "o.obj").string() + option).exit_code,
              2)
        << option;
  for (const auto& entry : fs::directory_iterator(dir_))
    EXPECT_EQ(entry.path().filename(), "sphere.off") << "left behind: " << entry.path();
}

TEST_F(Cli, BenchSolversAgreeAndRefuseSupportsLargerThanTheMesh) {
  const fs::path in = dir_ / "sphere.off";
  write_mesh(in.string(), make_icosphere(4)); // 2,562 vertices
  const CliRun r = run("bench solvers " + in.string() +
                       " --no-remesh --sizes 1000 --solvers ldlt,cg,multigrid,basis --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const auto& rows = j["supports"][0]["rows"];
  ASSERT_EQ(rows.size(), 4u);
  for (const auto& row : rows) {
    EXPECT_GE(row["moves_timed"].get<int>(), 1) << row;
    EXPECT_EQ(row["note"].get<std::string>().find("error"), std::string::npos) << row;
    EXPECT_LE(row["residual"].get<double>(), 1e-9) << row;
    EXPECT_LE(row["max_difference"].get<double>(), 1e-6) << row;
  }
  const CliRun too_big = run("bench solvers " + in.string() + " --no-remesh --sizes 5000");
  EXPECT_EQ(too_big.exit_code, 1);
  EXPECT_NE(too_big.err.find("too few for a support of 5000"), std::string::npos) << too_big.err;
}

// `remora bench edit --bake-first`: a move of a smaller region baked locally first, then the
// regions timed on the baked base; a bad count is a usage error.
TEST_F(Cli, BenchEditTimesRegionsOnABakedBase) {
  const fs::path in = dir_ / "sphere.off";
  write_mesh(in.string(), make_icosphere(4)); // 2,562 vertices
  const CliRun r = run("bench edit " + in.string() +
                       " --support 1200 --regions 2 --frames 2 --bake-first 300 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["bench"]["bake_first"], 300);
  EXPECT_EQ(j["bench"]["bake_first_kind"], "local");
  EXPECT_GT(j["bench"]["bake_first_ms"].get<double>(), 0.0);
  EXPECT_GT(j["bench"]["later_regions_ms_median"]["set_region"].get<double>(), 0.0);
  EXPECT_GT(j["region"]["free_base_vertices"].get<int>(),
            300); // the timed region, not the baked one
  EXPECT_EQ(run("bench edit " + in.string() + " --bake-first -1").exit_code, 2);
}

// `remora bench edit --method nonlinear --energy E`: the drag's frames and the converged result
// after it, under the energy asked for (the iterative one iterates); an unknown method is a usage
// error.
TEST_F(Cli, BenchEditTimesTheNonlinearMethod) {
  const fs::path in = dir_ / "sphere.off";
  write_mesh(in.string(), make_icosphere(4)); // 2,562 vertices
  for (const std::string energy : {"rotated-laplacian", "blended-motions"}) {
    const CliRun r =
        run("bench edit " + in.string() +
            " --support 1200 --frames 3 --method nonlinear --energy " + energy + " --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["bench"]["method"], "nonlinear");
    EXPECT_EQ(j["nonlinear"]["energy_name"], energy);
    EXPECT_TRUE(j["nonlinear"]["converged"].get<bool>()) << j["nonlinear"];
    EXPECT_EQ(j["nonlinear"]["fallback"], "");
    EXPECT_EQ(j["bench"]["frames"], 3);
    if (energy == "rotated-laplacian") {
      EXPECT_GE(j["nonlinear"]["total_iterations"].get<int>(), 1) << j["nonlinear"];
    }
  }
  EXPECT_EQ(run("bench edit " + in.string() + " --method arap").exit_code, 2);
}

// docs/editing.md's examples, run as documented: every ```json block on the bundled bunny, and
// the quick-flag form of the first one, which must give the same mesh.
TEST_F(Cli, EditRunsTheDocumentedExamples) {
  const std::string bunny = std::string(REMORA_REPO_DATA) + "/bunny.ply";
  const std::string doc = slurp(fs::path(REMORA_REPO_DATA) / ".." / "docs" / "editing.md");
  std::vector<std::string> examples;
  for (std::size_t at = doc.find("```json\n"); at != std::string::npos;
       at = doc.find("```json\n", at + 1)) {
    const std::size_t begin = at + 8, end = doc.find("```", begin);
    examples.push_back(doc.substr(begin, end - begin));
  }
  ASSERT_GE(examples.size(), 3u);
  // Under the sanitizers (make test-asan) only the first example runs: the others take the same
  // code paths on other regions, and each costs a preprocessing of the bunny (about 20 s there).
  if (std::getenv("REMORA_SANITIZED")) examples.resize(1);
  const std::size_t faces = read_mesh(bunny).mesh.n_faces();
  for (std::size_t i = 0; i < examples.size(); ++i) {
    const fs::path edit = dir_ / ("example" + std::to_string(i) + ".json");
    const fs::path out = dir_ / ("example" + std::to_string(i) + ".ply");
    std::ofstream(edit) << examples[i];
    const CliRun r =
        run("edit " + bunny + " --edit " + edit.string() + " -o " + out.string() + " --json");
    ASSERT_EQ(r.exit_code, 0) << examples[i] << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_GT(j["result"]["max_move_relative"].get<double>(), 1e-3) << i;
    EXPECT_LT(j["result"]["max_move_relative"].get<double>(), 0.2) << i;
    EXPECT_EQ(j["phong"]["encoded"], j["region"]["support_vertices"]) << i;
    EXPECT_EQ(read_mesh(out.string()).mesh.n_faces(), faces);
  }
  const fs::path quick = dir_ / "quick.ply";
  const CliRun r = run("edit " + bunny + " -o " + quick.string() +
                       " --support-sphere -0.03,0.15,0,0.05 --handle-sphere -0.03,0.17,0,0.015"
                       " --translate 0,0.02,0 --report");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("detail retention"), std::string::npos) << r.out;
  const Mesh a = read_mesh(quick.string()).mesh,
             b = read_mesh((dir_ / "example0.ply").string()).mesh;
  ASSERT_EQ(a.n_vertices(), b.n_vertices());
  double difference = 0;
  for (const VertexHandle v : a.vertices())
    difference = std::max(difference, (a.point(v) - b.point(v)).norm());
  EXPECT_LT(difference, 1e-12);
}

// --refine-support: the support's long edges split (the output has more vertices, the old ones
// first and where they were outside the support), counted in the report; refused with
// --no-remesh.
TEST_F(Cli, EditRefinesTheSupportWhenAsked) {
  const fs::path in = dir_ / "sphere.off";
  const Mesh sphere = make_icosphere(3); // radius 1
  write_mesh(in.string(), sphere);
  const fs::path out = dir_ / "out.ply";
  const std::string args = "edit " + in.string() + " -o " + out.string() +
                           " --support-sphere 0,0,1,0.8 --handle-sphere 0,0,1,0.2"
                           " --translate 0,0,0.1 --refine-support";
  const CliRun r = run(args + " --report");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("refined: "), std::string::npos) << r.out;
  const Mesh result = read_mesh(out.string()).mesh;
  EXPECT_GT(result.n_vertices(), sphere.n_vertices());
  for (const VertexHandle v : sphere.vertices())
    if (sphere.point(v)[2] < 0.0) {
      EXPECT_LT((result.point(v) - sphere.point(v)).norm(), 1e-6);
    }
  // The same edit as EDIT.json with "refine_support": the same mesh.
  const fs::path edit = dir_ / "refine.json";
  std::ofstream(edit) << R"({"refine_support": true,
    "support": {"sphere": {"center": [0, 0, 1], "radius": 0.8}},
    "handles": [{"region": {"sphere": {"center": [0, 0, 1], "radius": 0.2}},
                 "transform": {"translate": [0, 0, 0.1]}}]})";
  const fs::path out_json = dir_ / "out_json.ply";
  ASSERT_EQ(run("edit " + in.string() + " -o " + out_json.string() + " --edit " + edit.string())
                .exit_code,
            0);
  const Mesh from_json = read_mesh(out_json.string()).mesh;
  ASSERT_EQ(from_json.n_vertices(), result.n_vertices());
  for (const VertexHandle v : result.vertices()) EXPECT_EQ(from_json.point(v), result.point(v));
  fs::remove(out);
  const CliRun refused = run(args + " --no-remesh");
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_NE(refused.err.find("does not combine with --no-remesh"), std::string::npos)
      << refused.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(Cli, EditRefusesBadRequestsAndWritesNothing) {
  const fs::path in = dir_ / "sphere.off";
  write_mesh(in.string(), make_icosphere(3)); // radius 1
  const fs::path out = dir_ / "out.ply";
  const std::string base = "edit " + in.string() + " -o " + out.string() + " ";
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  };
  const std::string ok_handles =
      R"("handles": [{"region": {"sphere": {"center": [0, 0, 1], "radius": 0.3}}}])";
  const struct {
    std::string args;
    int code;
    std::string message;
  } cases[] = {
      {"--edit " + write("broken.json", "{\"support\": [1, 2"), 1, "not valid JSON"},
      {"--edit " + (dir_ / "missing.json").string(), 1, "cannot open"},
      {"--edit " + write("key.json", "{\"suport\": [1], " + ok_handles + "}"), 1,
       "unknown key 'suport'"},
      {"--edit " +
           write("empty.json", R"({"support": {"sphere": {"center": [5, 5, 5], "radius": 0.1}}, )" +
                                   ok_handles + "}"),
       1, "selects no vertex"},
      {"--edit " + write("outside.json",
                         R"({"support": {"sphere": {"center": [0, 0, -1], "radius": 0.5}}, )" +
                             ok_handles + "}"),
       1, "outside the support"},
      {"--edit " +
           write("ids.json", R"({"support": [1, 2, 100000], "handles": [{"region": [1]}]})"),
       1, "vertex 100000 of the file"},
      {"--support-sphere 0,0,1,0.8 --handle-sphere 0,0,1,0.2 --translate 1,nan,0", 1,
       "--translate"},
      {"--support-sphere 0,0,1,0.8 --handle-sphere 0,0,1 --translate 1,0,0", 1,
       "--handle-sphere: expected 4 numbers"},
      {"--support-sphere 0,0,1,0.8 --handle-sphere 0,0,1,0.2 --base-feature-cap -1", 2,
       "--base-feature-cap"},
      {"--edit " +
           write("cap.json", R"({"support": [1, 2], "base_feature_cap": -1, )" + ok_handles + "}"),
       1, "edit.base_feature_cap: must be >= 0"},
      {"--support-sphere 0,0,1,0.8", 2, "requires"},
      {"", 1, "nothing to edit"},
      {"--support-sphere 0,0,1,0.8 --handle-sphere 0,0,1,0.2 --solver ldlt --areas mixed", 1,
       "symmetric positive definite"},
  };
  for (const auto& c : cases) {
    const CliRun r = run(base + c.args);
    EXPECT_EQ(r.exit_code, c.code) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.args;
  }
}

// A file name that is not UTF-8 (Latin-1 on a Linux file system) is written into --json replaced
// by U+FFFD; the command succeeds.
TEST_F(Cli, JsonReportsOfFilesNamedInAnotherEncodingParse) {
  const fs::path in = dir_ / "\xe9t\xe9.off";
  write_mesh(in.string(), make_icosphere(1, 1.0));
  const CliRun r = run("info --json '" + in.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out, nullptr, false);
  ASSERT_FALSE(j.is_discarded()) << r.out;
  EXPECT_NE(j["load"]["path"].get<std::string>().find("\xef\xbf\xbd"), std::string::npos);
}

// The limits of docs/limits.md on the command line: a mesh over --max-triangles is refused before
// the work, an edit with more handles than --max-handles too, and no output file is left.
TEST_F(Cli, EditAndRemeshRefuseWhatIsOverTheirLimits) {
  const fs::path in = dir_ / "sphere.ply", out = dir_ / "out.ply";
  write_mesh(in.string(), make_icosphere(3, 1.0)); // 1,280 triangles
  const std::string quick =
      " --support-sphere 0,0,1,0.5 --handle-sphere 0,0,1,0.1 --translate 0,0,0.1";
  CliRun r = run("edit " + in.string() + " -o " + out.string() + quick + " --max-triangles 1000");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("over the limit of 1000 triangles"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  r = run("remesh " + in.string() + " -o " + out.string() + " --max-triangles 1000");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("over the limit of 1000 triangles"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  const fs::path edit = write_text(
      "three.json", R"({"support": {"sphere": {"center": [0, 0, 1], "radius": 0.8}}, "handles": [
        {"region": {"sphere": {"center": [0, 0, 1], "radius": 0.1}}},
        {"region": {"sphere": {"center": [0.5, 0, 0.85], "radius": 0.1}}},
        {"region": {"sphere": {"center": [-0.5, 0, 0.85], "radius": 0.1}}}]})");
  r = run("edit " + in.string() + " -o " + out.string() + " --edit " + edit.string() +
          " --max-handles 2");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("the edit has 3 handles; at most 2 are accepted"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out));
  r = run("edit " + in.string() + " -o " + out.string() + quick + " --max-triangles 1280");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  // The default is stated in the help, with how it was derived.
  r = run("edit --help");
  EXPECT_NE(r.out.find("this machine's"), std::string::npos) << r.out;
}

} // namespace
} // namespace remora
