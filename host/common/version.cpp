#include "host/common/version.h"

namespace host {

const char* version() {
  return VGPU_RT_VERSION;
}

}  // namespace host
