# Lab 02: SIMD.
#   Part B, one path per SIMD lane: ./lab02 (skeleton/, 8 lanes of AVX2, what students write)
#   and ./lab02-ref-avx2 (solution/, the same finished: the yardstick of the students' speed).
#   ./lab02-ref: the reference at the width the CPU has (16 AVX-512 lanes, else 8 of AVX2),
#   with compacted packets (render_widest.cpp over the SIMD library, SIMD_OBJ in Makefile).
#   ./lab02-bench: lab02-ref whose width and method RT_SIMD_LANES (8, 16) and RT_SIMD_COMPACT
#   (0, 1) choose, for the handout's table (tools/bench/simd.py).
#   Part A, the lab-01 renderer with an SSE Vec3: ./lab02a (with skeleton/part-a/vec3.h) and
#   ./lab02a-ref (with solution/part-a/vec3.h), each standing in for common/core/vec3.h.
#   ./lab02-prims, a worked example: SIMD across primitives (one ray, 8 triangles).
LAB02 := labs/02-simd

ifneq ($(filter x86_64% i686% i386%,$(shell $(CXX) -dumpmachine)),)

# ---- Part B ------------------------------------------------------------------------------
# render.cpp checks the CPU at run time and is built for any x86-64; render_avx2.cpp holds
# every AVX2 instruction and is the only file built with -mavx2 -mfma (no-ops under
# -march=native on an AVX2 machine; what lets another machine build it at all).
# Part B's objects see lab 02's SIMD library (common/simd/) on the include path.
$(BUILD)/$(LAB02)/%.o: LAB_INCLUDES = -Icommon/simd
# The skeleton's objects see skeleton/ first: its packet_hits.h (the student's intersection
# tests) stands in for common/simd/packet_hits.h, which packet_tracer.h includes.
$(BUILD)/$(LAB02)/skeleton/%.o: LAB_INCLUDES = -I$(LAB02)/skeleton -Icommon/simd
$(BUILD)/$(LAB02)/skeleton/render_avx2.o $(BUILD)/$(LAB02)/solution/render_avx2.o \
$(BUILD)/$(LAB02)/render_prims.o: CXXFLAGS += $(SIMD_AVX2_FLAGS)

lab02: $(BUILD)/$(LAB02)/skeleton/render.o $(BUILD)/$(LAB02)/skeleton/render_avx2.o $(COMMON_OBJ)
	$(CXX) $(CXXFLAGS) $^ $(INTO_TARGET)
lab02-ref-avx2: $(BUILD)/$(LAB02)/solution/render.o $(BUILD)/$(LAB02)/solution/render_avx2.o \
	$(COMMON_OBJ)
	$(CXX) $(CXXFLAGS) $^ $(INTO_TARGET)
# render_widest.cpp has no SIMD flags; SIMD_OBJ comes last (see Makefile).
lab02-ref: $(BUILD)/$(LAB02)/render_widest.o $(COMMON_OBJ) $(SIMD_OBJ)
	$(CXX) $(CXXFLAGS) $^ $(INTO_TARGET)
$(BUILD)/$(LAB02)/bench/render_widest.o: $(LAB02)/render_widest.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -DRT_PACKETS_FROM_ENV $(SIMD_INCLUDES) -c $< -o $@
lab02-bench: $(BUILD)/$(LAB02)/bench/render_widest.o $(COMMON_OBJ) $(SIMD_OBJ)
	$(CXX) $(CXXFLAGS) $^ $(INTO_TARGET)
# A worked example for comparison, not graded: SIMD across primitives (simd_geometry.h).
lab02-prims: $(BUILD)/$(LAB02)/solution/render.o $(BUILD)/$(LAB02)/render_prims.o \
	$(COMMON_OBJ)
	$(CXX) $(CXXFLAGS) $^ $(INTO_TARGET)

# ---- Part A ------------------------------------------------------------------------------
# Every file, the shared driver too, is built with solution/part-a (or skeleton/part-a) first
# on the include path, so its vec3.h replaces common/core/vec3.h everywhere, into an object folder
# of its own: Vec3 is 16 bytes there, not 12, so no object of the scalar build may be linked
# in.
LAB02A_SRC := $(LIB_SRC) common/host/lab_main.cpp common/host/main.cpp

$(BUILD)/vec3-sse-ref/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -I$(LAB02)/solution/part-a $(INCLUDES) -c $< -o $@
$(BUILD)/vec3-sse/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -I$(LAB02)/skeleton/part-a $(INCLUDES) -c $< -o $@

# render_vec3_sse.cpp is lab 01's pixel loop; the student's Part A is skeleton/part-a/vec3.h.
LAB02A_SRC += $(LAB02)/render_vec3_sse.cpp
lab02a-ref: $(patsubst %.cpp,$(BUILD)/vec3-sse-ref/%.o,$(LAB02A_SRC))
	$(CXX) $(CXXFLAGS) $^ $(INTO_TARGET)
lab02a: $(patsubst %.cpp,$(BUILD)/vec3-sse/%.o,$(LAB02A_SRC))
	$(CXX) $(CXXFLAGS) $^ $(INTO_TARGET)

# Variants (make variant): Part B as one AVX2 build; Part A against ./lab02a's driver
# objects, built with the skeleton's part-a/vec3.h (the same 16-byte Vec3 layout; only the
# operators' bodies differ), which a students' tree holds too, where the solution's is not.
# The variant's own objects come first on the link line, so its operators are the ones kept.
VARIANT_FLAGS_02-simd := -Icommon/simd $(SIMD_AVX2_FLAGS)
VARIANT_DRIVER_02-simd := $(COMMON_OBJ)
VARIANT_DRIVER_02-simd-a := $(patsubst %.cpp,$(BUILD)/vec3-sse/%.o,$(LIB_SRC) \
                            common/host/lab_main.cpp common/host/main.cpp)

else

$(LAB_TARGETS_02):
	@echo "$@: lab 02 needs an x86-64 CPU and compiler (SSE, AVX2); this is $(shell $(CXX) -dumpmachine)" >&2
	@exit 1
.PHONY: $(LAB_TARGETS_02)
UNBUILDABLE += $(LAB_TARGETS_02)

endif
