// The process's resident memory (memory.h).
#include "host/common/memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>

namespace host {

namespace {
struct Statm {
  uint64_t resident = 0, shared = 0;  // bytes
};
Statm statm() {
  Statm s;
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return s;
  unsigned long long size = 0, resident = 0, shared = 0;
  if (std::fscanf(f, "%llu %llu %llu", &size, &resident, &shared) == 3) {
    const uint64_t page = uint64_t(::sysconf(_SC_PAGESIZE));
    s.resident = resident * page;
    s.shared = shared * page;
  }
  std::fclose(f);
  return s;
}
}  // namespace

uint64_t file_resident_bytes() {
  return statm().shared;
}

uint64_t anon_resident_bytes() {
  const Statm s = statm();
  return s.resident > s.shared ? s.resident - s.shared : 0;
}

namespace {
const uint64_t g_startup_anon = anon_resident_bytes();
}  // namespace

uint64_t startup_anon_bytes() {
  return g_startup_anon;
}

uint64_t peak_resident_bytes() {
  rusage ru{};
  ::getrusage(RUSAGE_SELF, &ru);
  return uint64_t(ru.ru_maxrss) * 1024;
}

}  // namespace host
