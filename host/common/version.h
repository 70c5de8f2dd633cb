// The version of vgpu-rt, defined once: the VERSION file at the repository's root, which CMake
// reads into the project's version, the command line's --version, the statistics JSON, the
// report, the Python module's __version__ and the packages' names.
#pragma once

namespace host {

// "MAJOR.MINOR.PATCH", as in VERSION.
const char* version();

}  // namespace host
