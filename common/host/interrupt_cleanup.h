// Output temporaries that a SIGINT, SIGTERM or SIGHUP must not leave behind. AtomicFile
// writes into "<target>.partial-XXXXXX" and renames it over the target when done; if the
// process is interrupted before that, the handler installed here unlinks every temporary
// still registered, then lets the signal end the process as it would have (same exit status).
#pragma once

// Remembers `path` until forget_on_interrupt(path); returns false when all slots are taken
// (the file is then only cleaned up on normal exits). Not thread-safe: the driver registers
// its outputs from one thread before rendering.
bool remove_on_interrupt(const char* path);
void forget_on_interrupt(const char* path);
