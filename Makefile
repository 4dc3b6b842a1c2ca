# One entry point for people and CI. Every target installs what it needs first.
#   make demo    install deps, build, make a humanoid sample sequence (or BAG=file.bag),
#                run the whole pipeline on it headless, print and write the results
#   make test    install deps, build, run every gtest and rostest, print a summary
#   make build   install deps and build the catkin workspace under build/ws
#   make bench   the benchmark suite and end-to-end latency (figures, never pass/fail)
#   make eval    the plane core vs sequential MAGSAC on the AdelaideRMF dev scenes (DATA=folder)
#   make eval-euroc  the plane core on the EuRoC stereo pairs vs their known pose (EUROC=folder)
#   make sanitize  the unit tests built with AddressSanitizer + UBSan (build/ws_asan;
#                SANITIZE_ALL=1 also the long scene runs the short set leaves out)
#   make helgrind  data-race check: the nodelets' rostests under helgrind
#   make fuzz    libFuzzer targets of test/fuzz, FUZZ_SECONDS each (default 60)
#   make clean   remove build/

SHELL := /bin/bash
REPO  := $(CURDIR)
WS    := $(REPO)/build/ws
# catkin and Debian's pluginlib hooks call the first python3 on PATH: it must be Debian's.
export PATH := /usr/bin:$(PATH)
BUILD_TYPE ?= Release
JOBS ?= 2
CATKIN := source /opt/ros/noetic/setup.bash 2>/dev/null || true; cd $(WS) && catkin_make -j$(JOBS) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE)
DEVEL := $(WS)/devel/setup.bash
DATA ?= $(REPO)/../shared/data/adelaidermf_dev

.PHONY: deps link build demo test bench eval eval-euroc sanitize sanitize-build sanitize-run helgrind fuzz clean

deps:
	@scripts/install_deps.sh

# The package in the workspace links every top-level entry of the repository but
# build/ itself: linking the whole repository would make a loop that rosrun's
# `find -L` walks into and reports.
PKG := $(WS)/src/mono_plane_detection
link:
	@mkdir -p $(WS)/src
	@[ ! -L $(PKG) ] || rm $(PKG)
	@mkdir -p $(PKG)
	@# Only missing or wrong links are made: a build running meanwhile (CI's sanitizer build)
	@# never sees a link that is being replaced.
	@for f in $(REPO)/* $(REPO)/.ci; do [ "$$(basename $$f)" = build ] || \
	  [ "$$(readlink $(PKG)/$$(basename $$f))" = "$$f" ] || ln -sfn $$f $(PKG)/; done

build: deps link
	@echo "build: catkin_make in $(WS) (log: $(WS)/build.log)"
	@$(CATKIN) > $(WS)/build.log 2>&1 || { tail -40 $(WS)/build.log; exit 1; }

# The main job. BAG=your.bag [TRUTH=its.yaml] replays your own bag; RVIZ=1 shows rviz
# (installs it) instead of running headless; PROFILE=wheeled|humanoid; RESULTS=folder;
# CAMERA=namespace IMAGE=topic name: where the bag's images are (camera, image_raw).
RESULTS ?= $(REPO)/results
CAMERA ?= camera
IMAGE ?= image_raw
PROFILE ?= humanoid
FRAMES ?= 300
RVIZ ?= 0
demo: build
	@[ "$(RVIZ)" != 1 ] || scripts/install_deps.sh rviz libgl1-mesa-dri
	@source $(DEVEL) && DEMO_CAMERA=$(CAMERA) DEMO_IMAGE=$(IMAGE) scripts/demo.sh $(RESULTS) $(PROFILE) $(FRAMES) \
	  $(if $(filter 1,$(RVIZ)),true,false) $(if $(BAG),$(abspath $(BAG))) $(if $(TRUTH),$(abspath $(TRUTH)))

# The data-race check: both nodelet rostests with their manager (4 worker threads, three
# plane nodelets) under valgrind's helgrind, which sees every access and lock of the
# whole process, Debian's uninstrumented ROS included. Fails when a racing access is
# made by our code (scripts/helgrind_summary.py sorts the rest); XML reports in
# build/ws_helgrind/reports. About 10 minutes.
HG_WS := $(REPO)/build/ws_helgrind
HG_SCALE ?= 20
helgrind: deps
	@scripts/install_deps.sh valgrind
	@mkdir -p $(HG_WS)/src $(HG_WS)/reports
	@[ -e $(HG_WS)/src/mono_plane_detection ] || ln -sfn $(PKG) $(HG_WS)/src/mono_plane_detection
	@$(MAKE) --no-print-directory link
	@cd $(HG_WS) && catkin_make -j$(JOBS) -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  mono_plane_detection_nodelets test_plane_nodelet test_tracker_nodelet \
	  > $(HG_WS)/build.log 2>&1 || { tail -30 $(HG_WS)/build.log; exit 1; }
	@rm -f $(HG_WS)/reports/*
	@source $(HG_WS)/devel/setup.bash && failed=0 && for t in tracker_nodelet plane_nodelet; do \
	  rostest mono_plane_detection $$t.test time_limit:=1800 timeout_scale:=$(HG_SCALE) load_args:=--no-bond \
	    manager_prefix:="valgrind --tool=helgrind --error-limit=no --num-callers=40 --xml=yes --xml-file=$(HG_WS)/reports/$$t.%p.xml" \
	    > $(HG_WS)/$$t.log 2>&1 && echo "helgrind: $$t rostest passed" \
	    || { failed=1; echo "helgrind: $$t rostest FAILED"; tail -20 $(HG_WS)/$$t.log; }; \
	done; scripts/helgrind_summary.py $(HG_WS)/reports/*.xml && exit $$failed

fuzz: deps link
	@scripts/install_deps.sh clang
	@JOBS=$(JOBS) scripts/fuzz.sh

test: build
	@rm -rf $(WS)/build/test_results
	@# The test programs first, JOBS at a time (run_tests -j1 would build them one by one);
	@# the gtests JOBS at a time too (no ROS master, nothing timed); then the rostests and
	@# launch checks, two at a time, the longest first (scripts/run_rostests.sh: each
	@# replays images in real time through its own manager and master, about half a core).
	@$(CATKIN) tests > $(WS)/build_tests.log 2>&1 || { tail -40 $(WS)/build_tests.log; exit 1; }
	@$(CATKIN) run_tests_mono_plane_detection_gtest > $(WS)/run_tests.log 2>&1 || { tail -50 $(WS)/run_tests.log; exit 1; }
	@source $(DEVEL) && scripts/run_rostests.sh $(WS)/build 2 >> $(WS)/run_tests.log 2>&1 \
	  || { tail -50 $(WS)/run_tests.log; exit 1; }
	@scripts/summarize_tests.sh $(WS)/build/test_results

# The suite (ours against baselines, plot in $(RESULTS)/benchmark.png) and the latency
# through the nodelet manager. BENCH_ALL=1 adds the tracker's per-switch tables.
# BENCH_DATA: the folder with euroc_stereo/, tum_office_frames/ and adelaidermf_dev/ (real data).
BENCH_DATA ?= $(REPO)/../shared/data
bench: build
	@source $(DEVEL) && scripts/benchmark.sh $(RESULTS) $(BENCH_DATA)
	@[ "$(BENCH_ALL)" != 1 ] || { source $(DEVEL) && rosrun mono_plane_detection benchmark_tracker; }

eval: build
	@source $(DEVEL) && rosrun mono_plane_detection eval_two_view $(DATA)

# The plane core on the EuRoC stereo pairs, judged by their known relative pose
# (EUROC=folder with cam0/ cam1/, SEEDS runs per pair); the script needs numpy.
EUROC ?= $(REPO)/../shared/data/euroc_stereo
SEEDS ?= 8
eval-euroc: build
	@scripts/install_deps.sh python3-numpy
	@source $(DEVEL) && scripts/eval_euroc $(EUROC) --seeds $(SEEDS) \
	  --plane-pair $(WS)/devel/lib/mono_plane_detection/plane_pair

# Same sources, a second workspace with sanitizers (-O1 -g1: the sanitizers' usual level,
# line numbers in reports, quicker to compile than -O2 -g; the test programs' own files
# -O0, half the compile time of instrumented -O1). It builds and runs the gtests
# that need no ROS master but the command-line ones (CMakeLists.txt's sanitized_tests),
# JOBS at a time (scripts/run_sanitized.sh). Any report fails the run.
ASAN_WS := $(REPO)/build/ws_asan
SANITIZE_FLAGS := -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all
sanitize: deps
	@$(MAKE) --no-print-directory link
	@$(MAKE) --no-print-directory sanitize-build
	@$(MAKE) --no-print-directory sanitize-run

# The sanitized tests alone (after sanitize-build).
sanitize-run:
	@SANITIZE_ALL=$(SANITIZE_ALL) scripts/run_sanitized.sh $(ASAN_WS)/devel/lib/mono_plane_detection $(JOBS)

# The sanitizer workspace's build alone (after make build: deps and links in place).
sanitize-build:
	@mkdir -p $(ASAN_WS)/src
	@[ -e $(ASAN_WS)/src/mono_plane_detection ] || ln -sfn $(PKG) $(ASAN_WS)/src/mono_plane_detection
	@cd $(ASAN_WS) && catkin_make -j$(JOBS) -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DCMAKE_CXX_FLAGS="$(SANITIZE_FLAGS)" -DCMAKE_EXE_LINKER_FLAGS="$(SANITIZE_FLAGS)" \
	  -DCMAKE_SHARED_LINKER_FLAGS="$(SANITIZE_FLAGS)" -DMPD_TEST_COMPILE_OPTIONS=-O0 mono_plane_detection_sanitized_tests > $(ASAN_WS)/build.log 2>&1 \
	  || { tail -30 $(ASAN_WS)/build.log; exit 1; }

clean:
	rm -rf build
