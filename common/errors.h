// Bad input: a scene file, a flag, an output path. The shared main prints its message as one
// line and exits with status 2.
#pragma once

#include <stdexcept>
#include <string>

struct InputError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

constexpr int kExitBadInput = 2;
