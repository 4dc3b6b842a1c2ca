# One entry point for people and CI. Every target installs what it needs first.
#   make test    install deps, build, run every gtest and rostest, print a summary
#   make build   install deps and build the catkin workspace under build/ws
#   make bench   run the benchmark programs (figures, never pass/fail)
#   make eval    segment_planes on the AdelaideRMF dev scenes (DATA=folder)
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

.PHONY: deps link build test bench eval clean

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
	@for f in $(REPO)/* $(REPO)/.ci; do [ "$$(basename $$f)" = build ] || ln -sfn $$f $(PKG)/; done

build: deps link
	@$(CATKIN)

test: build
	@rm -rf $(WS)/build/test_results
	@$(CATKIN) run_tests -j1 > $(WS)/run_tests.log 2>&1 || { tail -50 $(WS)/run_tests.log; exit 1; }
	@scripts/summarize_tests.sh $(WS)/build/test_results

bench: build
	@source $(DEVEL) && rosrun mono_plane_detection benchmark_tracker
	@source $(DEVEL) && rosrun mono_plane_detection benchmark_planes

eval: build
	@source $(DEVEL) && scripts/eval_two_view $(DATA)

clean:
	rm -rf build
