// A reference renders in double what float cannot place (scene_limits.h), without being
// asked: its binary carries its double build as data (double_twin.S, linked into the
// references only: labs' lab.mk, `double_twin` in the Makefile), and hands such a scene to it
// by running it in its place, with the same command line. Nothing else changes for a float
// scene: the float renderer is the same code, and the twin's bytes are never read. A binary
// without a twin (every student build) refuses the scene in one line, as before.
#pragma once

// Whether this binary carries a double build.
bool has_double_twin();

// Replaces this process with the double build, given the same argv; returns only when that
// cannot be done, with the reason. Where RT_DOUBLE_TWIN names a file, that file is the double
// build (the grader's sandbox runs only files it staged, and stages the twin it finds in this
// binary: labkit/double_twin.py); else the carried bytes run from an anonymous memory file.
const char* run_double_twin(char** argv);
