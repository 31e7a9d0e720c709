// The unit-test binary links every common object, lab_main.o included, which expects one
// lab to provide kLabName and render(). No unit test renders through lab_main, so these
// stubs only satisfy the linker.
#include "lab.h"

const char* const kLabName = "unit-tests";

RenderStats render(const RenderJob&, Image&) { return {}; }
