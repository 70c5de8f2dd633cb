// The process's resident memory, for the memory model (host/report/memory_json.h): what it
// holds now and its peak so far, as the system counts them (pages touched, code included), and
// the bytes of the arrays the model counts.
#pragma once

#include <cstdint>

namespace host {

// The bytes a vector's elements take (its size, not its capacity: the pages it wrote), for the
// memory model's counted terms.
template <class V>
uint64_t vector_bytes(const V& v) {
  return uint64_t(v.size()) * sizeof(typename V::value_type);
}

// The pages resident now (/proc/self/statm; 0 where the system does not say): those of files
// (the program's and its libraries' code and data, shared with other processes), and the rest
// (anonymous: what the process allocated).
uint64_t file_resident_bytes();
uint64_t anon_resident_bytes();
uint64_t peak_resident_bytes();  // the peak so far (getrusage's ru_maxrss)
// The anonymous pages resident when the program started (its static initialization, before
// any scene).
uint64_t startup_anon_bytes();

}  // namespace host
