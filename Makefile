# Remora's two entry points: `make demo` and `make test`. Both install what is missing
# (scripts/bootstrap.sh), configure and build. `make bench` runs the benchmarks, including the
# remeshing race against CGAL, which is GPL and therefore only ever built by that target.
BUILD      ?= build
ASAN_BUILD ?= build-asan
TSAN_BUILD ?= build-tsan
FUZZ_BUILD ?= build-fuzz
ASAN_CXX   ?= clang++
JOBS       ?= $(shell nproc)
CMAKE_FLAGS ?=
DEMO_MESH  ?= data/bunny.ply
BENCH_ARGS ?=
PORT       ?= 8080
# Unity builds (CMake batches: the library's, the apps' and the test files' groups of
# tests/CMakeLists.txt, one translation unit each) take half the compile time of a build from
# scratch; UNITY=OFF compiles every file alone (quicker rebuilds after editing one file, and a
# missing include is not hidden by an earlier file of its batch).
UNITY      ?= ON
# Debian's interpreter, which has Debian's numpy, scipy and pybind11, even when another python3
# (pyenv, conda) comes first on PATH; the Python module is built for it and tested with it.
PYTHON     ?= $(firstword $(wildcard /usr/bin/python3) python3)

PHONY_EXTRA = deps-web serve
.PHONY: all deps deps-bench $(PHONY_EXTRA) build demo test test-release test-asan test-tsan fuzz soak \
        bench format format-check clean

all: build

deps:
	@scripts/bootstrap.sh

deps-bench:
	@scripts/bootstrap.sh --bench

deps-web:
	@scripts/bootstrap.sh --web

# REMORA_WITH_CGAL=OFF is explicit so that a build folder `make bench` configured goes back to
# the CGAL-free default; the Google Benchmark programs are built by `make bench` only (the
# `remora bench` commands are part of the CLI and always built).
build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DREMORA_WERROR=ON -DREMORA_WITH_CGAL=OFF \
	  -DREMORA_BUILD_BENCH=OFF -DPython3_EXECUTABLE=$(PYTHON) -DCMAKE_UNITY_BUILD=$(UNITY) \
	  $(CMAKE_FLAGS)
	cmake --build $(BUILD) -j$(JOBS)

# The quality report of the bundled scan, its area-equalizing remesh (paper §4), one edit from
# the command line (lift the left ear and twist it), then the editor in the browser: open the
# URL it prints (Ctrl+C stops the server).
demo: build
	$(BUILD)/bin/remora info $(DEMO_MESH)
	$(BUILD)/bin/remora remesh $(DEMO_MESH) -o $(BUILD)/demo_remeshed.ply --report
	$(BUILD)/bin/remora edit $(DEMO_MESH) -o $(BUILD)/demo_edited.ply \
	    --support-sphere -0.03,0.15,0,0.05 --handle-sphere -0.03,0.17,0,0.015 \
	    --translate 0,0.02,0 --rotate 0,1,0,20 --report
	$(BUILD)/bin/remora serve $(DEMO_MESH) --port $(PORT)

# The browser editor alone.
serve: build
	$(BUILD)/bin/remora serve $(DEMO_MESH) --port $(PORT)

# The pictures in docs/images/ (bunny_ear, acrossriver_lift, base_area, needles_base,
# cylinder_twist, bunny_ear_twist), rendered
# from real results: `remora serve` edits, the page draws in headless chromium
# (scripts/render_pictures.mjs; chromium is installed when missing). The shared meshes come from
# ../shared/data (or REMORA_DATA); a missing one skips its picture. Not part of `make test`, whose
# WebEditor.Pictures runs the same script at a low resolution into the build folder. Then
# python_tutorial.png, which docs/python.md's tutorial draws with matplotlib
# (scripts/python_tutorial.py; Python.test_docs runs it in `make test`).
.PHONY: pictures
pictures: build
	@scripts/bootstrap.sh --web
	node scripts/render_pictures.mjs --out docs/images --cli $(BUILD)/bin/remora --web-root $(BUILD)/web
	PYTHONPATH=$(BUILD)/python $(PYTHON) scripts/python_tutorial.py --out docs/images/python_tutorial.png

# The browser editor's latency (web/tests/bench.mjs): `remora serve` on MESH, the real page driven
# with the mouse in headless chromium; the last line printed is one JSON object of medians in
# milliseconds (ready_ms, paint_move_ms, mouseup_to_gizmo_ms, drag_cycle_ms, drag_cycle_shown_ms,
# bake_ms), bytes_per_frame and support_vertices. BENCH_WEB_ARGS go to the script, e.g.
# BENCH_WEB_ARGS="--support-radius 0.05". Not part of `make test`.
MESH ?= data/bunny.ply
BENCH_WEB_ARGS ?=
.PHONY: bench-web
bench-web: build
	@scripts/bootstrap.sh --web
	node web/tests/bench.mjs --cli $(BUILD)/bin/remora --web-root $(BUILD)/web --mesh $(MESH) $(BENCH_WEB_ARGS)

# Release build with warnings as errors, the formatting check, then the unit tests again under
# AddressSanitizer + UndefinedBehaviorSanitizer with a smoke run of every fuzz harness, and the
# server's tests under ThreadSanitizer.
test: deps-web format-check test-release test-asan test-tsan

# ctest runs $(JOBS) test processes at once; OpenMP threads that spin while waiting and OpenBLAS's
# own threads then fight over the cores (the solver tests took 15-36 s instead of 0.2-2 s), so
# waiting threads sleep and OpenBLAS stays on one thread per test.
TEST_ENV = OMP_WAIT_POLICY=PASSIVE OPENBLAS_NUM_THREADS=1

test-release: build
	cd $(BUILD) && $(TEST_ENV) ctest --output-on-failure -j$(JOBS)

# The sanitized build is compiled by clang at -O1 -g1 (line tables only): -O1 -g1 takes 40 % less
# compile time than -O2 -g on the test files, and clang a third less than GCC under the
# sanitizers; the same checks, stack traces with file and line, and a second compiler's warnings.
#
# The tests that ASAN_RELEASE_ONLY matches run in the release build only: numerical figures on
# large inputs (the shared meshes' remesh suites, but for two CAD parts, gears and featuretype,
# whose slivers and creases reach the most code; the solver and multigrid agreements; the large
# ray-caster tree; the bitwise remesh comparisons; the cylinder's radii). Their code runs under
# the sanitizers through the smaller tests of the same steps; they took half of the sanitized
# run's time.
ASAN_RELEASE_ONLY = ^(CiMeshes/.*/(scans_bunny_ply|open_camelhead_off|heightfield_AcrossRiver_stl|cad_conrod_stl)|OpenMeshes/|ClosedMeshes/|SharedData/|QualityData\.|Meshes/RemeshPinned\.|Solver\.EverySolverAgrees|Multigrid\.AgreesWithTheDirectSolver|Remesh\.FineTuningFlipsLeaveADelaunayMesh|RayCaster\.ALargeMeshsTree|Editor\.NeedleMeshes|Nonlinear\.TheCylinderKeeps|NonlinearPropagated\.KeepsTheCylinders|RemeshGears\.NoFlatFacesAtAnotherLength)
test-asan: deps
	cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DREMORA_WERROR=ON \
	  -DCMAKE_CXX_COMPILER=$(ASAN_CXX) \
	  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DREMORA_SANITIZE=ON \
	  -DREMORA_BUILD_BENCH=OFF -DREMORA_BUILD_WEB=OFF -DREMORA_BUILD_FUZZ=ON -DCMAKE_UNITY_BUILD=$(UNITY) \
	  $(CMAKE_FLAGS)
	cmake --build $(ASAN_BUILD) -j$(JOBS)
	cd $(ASAN_BUILD) && $(TEST_ENV) REMORA_SANITIZED=1 ASAN_OPTIONS=detect_leaks=1 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 FUZZ_NICE=0 ctest --output-on-failure -j$(JOBS) \
	  -E '$(ASAN_RELEASE_ONLY)'

# The server's tests (test_server*.cpp: sessions, handlers, the HTTP binding, concurrent clients)
# under ThreadSanitizer, in a build of the library, the server and those tests only. OpenMP's
# synchronization is made visible to TSan by LLVM's Archer tool (libarcher, shipped with clang);
# what the uninstrumented libraries (libomp, libstdc++, cpp-httplib) do inside is not checked.
TSAN_OPTIONS_ALL = halt_on_error=1:second_deadlock_stack=1:history_size=4:ignore_noninstrumented_modules=1
test-tsan: deps
	cmake -S . -B $(TSAN_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DREMORA_WERROR=ON \
	  -DCMAKE_CXX_COMPILER=$(ASAN_CXX) \
	  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DREMORA_SANITIZE_THREAD=ON \
	  -DREMORA_BUILD_BENCH=OFF -DREMORA_BUILD_WEB=OFF -DCMAKE_UNITY_BUILD=$(UNITY) $(CMAKE_FLAGS)
	cmake --build $(TSAN_BUILD) -j$(JOBS) --target remora_tests
	cd $(TSAN_BUILD) && $(TEST_ENV) REMORA_SANITIZED=1 TSAN_OPTIONS=$(TSAN_OPTIONS_ALL) \
	  OMP_TOOL_LIBRARIES=$$($(ASAN_CXX) -print-resource-dir)/../../libarcher.so \
	  ctest --output-on-failure -j$(JOBS)

# Coverage-guided fuzzing (docs/fuzzing.md): every harness for FUZZ_SECONDS (default 180) in a
# clang build with ASan + UBSan, assertions on and our code instrumented for libFuzzer; corpora
# grow in $(FUZZ_BUILD)/fuzz-corpus, crashing inputs are kept in $(FUZZ_BUILD)/fuzz-crashes.
# ASan records no allocation stacks here (a fifth of the time of a small input); replaying a
# kept input with the harness alone gives them.
# FUZZ_HARNESSES picks some (e.g. "obj server"); FUZZ_RUNS stops each after that many executions
# (e.g. 10000000 for a long run). Runs under nice -n 19. Not part of `make test`.
FUZZ_SECONDS   ?= 180
FUZZ_HARNESSES ?=
FUZZ_RUNS      ?=
fuzz: deps
	cmake -S . -B $(FUZZ_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DREMORA_WERROR=ON \
	  -DCMAKE_CXX_COMPILER=$(ASAN_CXX) -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1" \
	  -DREMORA_SANITIZE=ON -DREMORA_BUILD_FUZZ=ON -DREMORA_FUZZ_COVERAGE=ON \
	  -DREMORA_BUILD_TESTS=OFF -DREMORA_BUILD_BENCH=OFF -DREMORA_BUILD_WEB=OFF $(CMAKE_FLAGS)
	cmake --build $(FUZZ_BUILD) -j$(JOBS) --target remora_fuzzers
	FUZZ_SECONDS=$(FUZZ_SECONDS) FUZZ_RUNS=$(FUZZ_RUNS) ASAN_OPTIONS=detect_leaks=1:malloc_context_size=0 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 scripts/fuzz.sh $(FUZZ_BUILD) $(FUZZ_HARNESSES)

# The soak of `remora serve` (scripts/soak.py; docs/server.md): SOAK_SECONDS (default 600) of
# random valid and invalid requests from SOAK_CLIENTS clients on loopback against one server on
# SOAK_MESH, with its memory sampled, every answer checked and the final state compared with a
# replay of the accepted requests; the report goes to $(BUILD)/soak.json. Under nice -n 19.
# Not part of `make test`.
SOAK_SECONDS ?= 600
SOAK_CLIENTS ?= 4
SOAK_MESH    ?= data/bunny.ply
soak: build
	nice -n 19 python3 scripts/soak.py --cli $(BUILD)/bin/remora --mesh $(SOAK_MESH) \
	  --seconds $(SOAK_SECONDS) --clients $(SOAK_CLIENTS) --report $(BUILD)/soak.json

# Every mesh of the shared data (DATA, default ../shared/data: the paths its MANIFEST.md lists)
# through load, preprocessing and an edit with its checks (remora bench pipeline); the table
# goes to stdout and $(BUILD)/pipeline-data.md (docs/benchmarks.md keeps it). Not in `make test`.
DATA ?= $(or $(REMORA_DATA),../shared/data)
.PHONY: pipeline-data
pipeline-data: build
	$(BUILD)/bin/remora bench pipeline $(DATA) > $(BUILD)/pipeline-data.md; status=$$?; \
	  cat $(BUILD)/pipeline-data.md; exit $$status

# Release build with the CGAL race, then loading speed (remora_bench) and the race
# (remora_bench_remesh). BENCH_ARGS go to the race, e.g. make bench BENCH_ARGS="--large --json".
bench: deps-bench
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DREMORA_WERROR=ON -DREMORA_BUILD_BENCH=ON \
	  -DREMORA_WITH_CGAL=ON $(CMAKE_FLAGS)
	cmake --build $(BUILD) -j$(JOBS)
	$(BUILD)/bench/remora_bench
	$(BUILD)/bench/remora_bench_remesh $(BENCH_ARGS)

FORMAT_FILES = $(shell git ls-files '*.h' '*.cpp')

format:
	clang-format -i $(FORMAT_FILES)

format-check:
	@clang-format --dry-run --Werror $(FORMAT_FILES) && echo "format-check: clean"

clean:
	rm -rf $(BUILD) $(ASAN_BUILD) $(TSAN_BUILD) $(FUZZ_BUILD) build-pip
