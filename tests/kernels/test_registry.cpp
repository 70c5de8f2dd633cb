// The one kernel list (kernels/kernel_list.h) against what is written about it: the glossary in
// kernels/README.md names every kernel of the list, with its C++ type, once, and nothing else;
// the registry's names are distinct; and only the kernels the README says derive from another do.
#include <doctest/doctest.h>

#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "kernels/registry.h"

namespace {

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" `");
  const auto b = s.find_last_not_of(" `");
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

// The glossary's rows: (kernel name as `vgpu-rt kernels` prints it, C++ type), from every table
// whose header's first cell starts with "Kernel" and whose second is "C++ type".
std::vector<std::pair<std::string, std::string>> glossary_rows(const std::string& path) {
  std::ifstream in(path);
  REQUIRE_MESSAGE(in.good(), "cannot open ", path);
  std::vector<std::pair<std::string, std::string>> rows;
  bool in_table = false;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] != '|') {
      in_table = false;
      continue;
    }
    std::vector<std::string> cells;
    std::stringstream ss(line.substr(1));
    for (std::string c; std::getline(ss, c, '|');) cells.push_back(trim(c));
    if (cells.size() < 2) continue;
    if (cells[0].rfind("Kernel", 0) == 0) {
      in_table = cells[1] == "C++ type";
    } else if (in_table && cells[0].find_first_not_of('-') != std::string::npos) {
      rows.emplace_back(cells[0], cells[1]);
    }
  }
  return rows;
}

template <class... K>
struct Types {};
#define VGPU_LIST_TYPE(K, file) , kernels::K
using AllKernels = Types<void VGPU_ALL_KERNELS(VGPU_LIST_TYPE)>;
#undef VGPU_LIST_TYPE

// "B from A" for every pair of listed kernels where B derives from A.
template <class... K>
std::set<std::string> derivations(Types<void, K...>) {
  std::set<std::string> out;
  // The name built in place: g++ 12 at -O1 warns (-Warray-bounds, a false positive) on the
  // temporaries of name + " from " + name.
  const auto pair = [](const char* b, const char* a) {
    std::string s(b);
    s.append(" from ").append(a);
    return s;
  };
  auto from_any = [&]<class B>() {
    ((std::is_base_of_v<K, B> && !std::is_same_v<K, B> ? void(out.insert(pair(B::name, K::name)))
                                                       : void()),
     ...);
  };
  (from_any.template operator()<K>(), ...);
  return out;
}

std::string dashed(std::string s) {
  for (char& c : s)
    if (c == ' ') c = '-';
  return s;
}

}  // namespace

TEST_CASE(
    "the kernels' glossary names every registered kernel with its C++ type, and nothing else") {
  const auto programs = kernels::all_programs(kernels::Programs::with_looping);
  const auto types = kernels::all_type_names();
  REQUIRE(programs.size() == types.size());
  std::map<std::string, std::string> registered;  // name -> type
  for (size_t i = 0; i < programs.size(); ++i) {
    const std::string name = dashed(programs[i]->name());
    CHECK_MESSAGE(registered.count(name) == 0, "two kernels are named ", name);
    registered[name] = types[i];
  }
  const auto rows = glossary_rows(std::string(VGPU_TEST_DATA) + "/../../kernels/README.md");
  std::map<std::string, std::string> written;
  for (const auto& [bound_name, bound_type] : rows) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& name = bound_name;
    const auto& type = bound_type;
    CHECK_MESSAGE(written.count(name) == 0, "kernels/README.md has two rows for ", name);
    written[name] = type;
  }
  for (const auto& [bound_name, bound_type] : registered) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& name = bound_name;
    const auto& type = bound_type;
    INFO("registered kernel ", name, " (", type, ")");
    REQUIRE_MESSAGE(written.count(name) == 1, "kernels/README.md has no row for it");
    CHECK(written[name] == type);
  }
  for (const auto& [bound_name, bound_type] : written) {
    // Named copies: clang 14 cannot capture a structured binding (CAPTURE, INFO).
    const auto& name = bound_name;
    const auto& type = bound_type;
    INFO("kernels/README.md row ", name, " (", type, ")");
    CHECK_MESSAGE(registered.count(name) == 1, "no registered kernel has that name");
  }
}

TEST_CASE("only generate sample rays and generate dense rays derive from another kernel") {
  CHECK(derivations(AllKernels{}) ==
        std::set<std::string>{"generate dense rays from generate rays",
                              "generate sample rays from generate rays"});
}
