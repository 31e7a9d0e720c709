# Lab 02: SIMD.
#   Part B, 8 paths per AVX2 packet (one per lane): ./lab02 (skeleton/) and ./lab02-ref
#   (solution/).
#   Part A, the lab-01 renderer with the SSE Vec3 of common/vec3_sse.h: ./lab02a (with
#   skeleton/vec3_sse.h) and ./lab02a-ref (with common/vec3_sse.h).
#   ./lab02-prims, a worked example: SIMD across primitives (one ray, 8 triangles).
LAB02 := labs/02-simd

ifneq ($(filter x86_64% i686% i386%,$(shell $(CXX) -dumpmachine)),)

# ---- Part B ------------------------------------------------------------------------------
# render.cpp checks the CPU at run time and is built for any x86-64; render_avx2.cpp holds
# every AVX2 instruction and is the only file built with -mavx2 -mfma (no-ops under
# -march=native on an AVX2 machine; what lets another machine build it at all).
$(BUILD)/$(LAB02)/skeleton/render_avx2.o $(BUILD)/$(LAB02)/solution/render_avx2.o \
$(BUILD)/$(LAB02)/render_prims.o: CXXFLAGS += -mavx2 -mfma

lab02: $(BUILD)/$(LAB02)/skeleton/render.o $(BUILD)/$(LAB02)/skeleton/render_avx2.o $(COMMON_OBJ)
	$(CXX) $(CXXFLAGS) $^ -o $@
lab02-ref: $(BUILD)/$(LAB02)/solution/render.o $(BUILD)/$(LAB02)/solution/render_avx2.o \
	$(COMMON_OBJ)
	$(CXX) $(CXXFLAGS) $^ -o $@
# A worked example for comparison, not graded: SIMD across primitives (simd_geometry.h).
lab02-prims: $(BUILD)/$(LAB02)/solution/render.o $(BUILD)/$(LAB02)/render_prims.o \
	$(COMMON_OBJ)
	$(CXX) $(CXXFLAGS) $^ -o $@

# ---- Part A ------------------------------------------------------------------------------
# Every file is built with -DRT_VEC3_SSE, into an object folder of its own: Vec3 is 16 bytes
# there, not 12, so no object of the scalar build may be linked in. The student's build
# searches skeleton/ before common/ for vec3_sse.h (vec3.h includes it with <>).
LAB02A_SRC := $(LIB_SRC) common/lab_main.cpp common/main.cpp

$(BUILD)/vec3-sse-ref/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -DRT_VEC3_SSE $(INCLUDES) -c $< -o $@
$(BUILD)/vec3-sse/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -DRT_VEC3_SSE -I$(LAB02)/skeleton $(INCLUDES) -c $< -o $@

# render_vec3_sse.cpp is lab 01's pixel loop; the student's Part A is skeleton/vec3_sse.h.
LAB02A_SRC += $(LAB02)/render_vec3_sse.cpp
lab02a-ref: $(patsubst %.cpp,$(BUILD)/vec3-sse-ref/%.o,$(LAB02A_SRC))
	$(CXX) $(CXXFLAGS) $^ -o $@
lab02a: $(patsubst %.cpp,$(BUILD)/vec3-sse/%.o,$(LAB02A_SRC))
	$(CXX) $(CXXFLAGS) $^ -o $@

LAB_BINARIES += lab02 lab02-ref lab02a lab02a-ref lab02-prims

else

lab02 lab02-ref lab02a lab02a-ref lab02-prims:
	@echo "$@: lab 02 needs an x86-64 CPU and compiler (SSE, AVX2); this is $(shell $(CXX) -dumpmachine)" >&2
	@exit 1

endif

.PHONY: lab02 lab02-ref lab02a lab02a-ref lab02-prims
