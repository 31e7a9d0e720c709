// What the shared main turns into one error line and an exit status.

// Bad input: a scene file, a flag, an output path. The shared main prints its message as one
// line and exits with status 2.
#pragma once

#include <stdexcept>
#include <string>

struct InputError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

constexpr int kExitBadInput = 2;

// Bad input for float only: a scene the double build places (scene_limits.h). A reference
// that carries its double build hands such a scene to it (double_twin.h); any other binary
// prints the message like any InputError.
struct PrecisionError : InputError {
    using InputError::InputError;
};

// The machine cannot do the render: no GPU, a GPU fault, device memory exhausted. Not the
// input's fault, so it has a status of its own; the shared main prints its message as one
// line, removes any half-written output and exits with status 3.
struct DeviceError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

constexpr int kExitDeviceError = 3;
