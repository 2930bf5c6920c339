// What the machine can hold: used to refuse work whose estimate exceeds it.
#pragma once
#include <cstddef>
#include <cstdint>

namespace abcube {

// MemAvailable from /proc/meminfo in bytes (or total RAM if that line is missing).
uint64_t available_memory_bytes();

// Peak resident set size of this process so far, in bytes (getrusage).
uint64_t peak_rss_bytes();

// Hands the heap's free pages back to the system (glibc malloc_trim; nothing elsewhere).
// Called after a large loader's many small blocks are freed, so that they stop counting in
// the resident set before the render allocates.
void release_free_memory();

// Process-wide: blocks of 256 KiB and more are mapped on their own and unmapped when freed
// (glibc's default threshold grows with the blocks freed, keeping large freed vectors in
// the heap). For programs (the CLI), never called by the library.
void map_large_blocks_alone();

}  // namespace abcube
