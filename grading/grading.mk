# The grader's make targets (make grade, gradescope, release, grade-batch).
# `make grade` itself is in the Makefile; grading/README.md explains the grader.

.PHONY: gradescope grade-batch grade-slurm release

# make gradescope LAB=NN: the Gradescope autograder zip for lab NN in build/.
gradescope:
	$(PYTHON) -m grading.releases.gradescope $(LAB)

# make grade-batch LAB=NN SUBMISSIONS=DIR [REPORT=DIR] [ONLY=flagged]: one folder or hand-in
# zip per student, graded in the sandbox; REPORT (default grades/) gets each results.json,
# grades.csv and report.html. ONLY=flagged regrades the students that REPORT flagged, with
# its saved secret.
grade-batch:
	@test -n "$(SUBMISSIONS)" || { echo "grade-batch: needs SUBMISSIONS=DIR" >&2; exit 2; }
	@$(PYTHON) -m grading.classes.batch $(LAB) $(SUBMISSIONS) --out $(or $(REPORT),grades) \
	    $(if $(ONLY),--only $(ONLY))

# make release LAB=NN OUT=DIR: the student repository for lab NN (grading/releases/release.py). LAB and
# OUT have defaults in the Makefiles (for make grade, make gpu-check); a release must name both.
release:
	@test "$(origin LAB)" != file -a "$(origin OUT)" != file -a -n "$(OUT)" || \
	    { echo "release: needs LAB=NN and OUT=DIR" >&2; exit 2; }
	@test -f grading/releases/release.py || \
	    { echo "release: made from the course repository; this is a release" >&2; exit 2; }
	@$(PYTHON) -c 'import numpy' 2>/dev/null || \
	    { echo "release: $(PYTHON) has no numpy: run make deps first (it installs what the grader needs)" >&2; exit 2; }
	@$(PYTHON) -m grading.releases.release '$(LAB)' '$(OUT)'

# The driver objects a variant of VARIANT_LAB links, and nothing else: the grader builds them
# in a students' tree (grading/students_tree.py) before compiling a submission there.
.PHONY: variant-driver cuda-variant-driver
variant-driver: $(VARIANT_DRIVER_$(VARIANT_LAB))
cuda-variant-driver: $(COMMON_OBJ)

# ThreadSanitizer builds, for lab 03's race check (grading/checks/races.py): LLVM's clang and
# OpenMP runtime, whose Archer tool tells ThreadSanitizer what OpenMP's barriers and loops
# order (GCC's libgomp tells it nothing, and every barrier would read as a race). The lab's
# own files at -O0, so that a variable its threads share is read and written in memory as the
# source says, not kept in a register where no tool sees it (and no image shows it); the
# driver, which has no threads, at -O1. `make lab03-race` builds your labs/03-openmp/skeleton
# so (make grade LAB=03 does); race-variant builds a hand-in folder, in the grader's sandbox.
.PHONY: race-variant race-variant-driver
RACE_CXX    ?= clang++
RACE_BUILD  := $(BUILD)/race
RACE_FLAGS  := -std=c++17 -g -fsanitize=thread -fopenmp -ffp-contract=off -w \
               -DRT_SOURCE_DIR='"$(CURDIR)"'
RACE_DRIVER := $(COMMON_OBJ:$(BUILD)/%=$(RACE_BUILD)/%)
$(RACE_BUILD)/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(RACE_CXX) $(RACE_FLAGS) -O1 $(INCLUDES) -c $< -o $@
race-variant-driver: $(RACE_DRIVER)
race-variant: $(RACE_DRIVER)
	@test -n "$(VARIANT)" || { echo "race-variant: needs VARIANT=DIR" >&2; exit 2; }
	$(RACE_CXX) $(RACE_FLAGS) -O0 -I'$(VARIANT)' $(INCLUDES) \
	    $(call quoted,$(sort $(wildcard $(VARIANT)/*.cpp))) $(RACE_DRIVER) -o '$(VARIANT)/lab'
lab03-race: $(RACE_DRIVER) $(wildcard $(LAB03)/skeleton/*.cpp $(LAB03)/skeleton/*.h)
	$(RACE_CXX) $(RACE_FLAGS) -O0 -I$(LAB03)/skeleton $(INCLUDES) $(wildcard $(LAB03)/skeleton/*.cpp) \
	    $(RACE_DRIVER) $(INTO_TARGET)

# make test-gradescope: the lab-01 Gradescope bundle built into a Docker image on a debootstrap
# Debian base and graded in containers with Docker's default seccomp at 0.5 CPU and 768 MB
# (grading/releases/gradescope_image/test_gradescope.py). Needs Docker and debootstrap; not part
# of make test. A script beside its Dockerfile, run by path with the repository on the import path.
.PHONY: test-gradescope
test-gradescope:
	PYTHONPATH=$(CURDIR) $(PYTHON) grading/releases/gradescope_image/test_gradescope.py
# make grade-slurm LAB=NN SUBMISSIONS=DIR [REPORT=DIR] [PARTITION=P] [TIME=H:MM:SS] [MEM=4G]
# [ONLY=flagged]: the same as a Slurm job array, one task per submission, and a merge job for
# grades.csv and report.html (grading/classes/slurm.py, which says its defaults); the tasks run
# $(PYTHON) by name. ONLY=flagged submits the tasks of the students REPORT flagged.
grade-slurm:
	@test -n "$(SUBMISSIONS)" || { echo "grade-slurm: needs SUBMISSIONS=DIR" >&2; exit 2; }
	@$(PYTHON) -m grading.classes.slurm $(LAB) $(SUBMISSIONS) --out $(or $(REPORT),grades) \
	    --python $(PYTHON) $(if $(PARTITION),--partition $(PARTITION)) \
	    $(if $(TIME),--time $(TIME)) $(if $(MEM),--mem $(MEM)) $(if $(ONLY),--only $(ONLY))
