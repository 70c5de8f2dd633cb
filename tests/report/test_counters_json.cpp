// The report room's JSON of the vgpu's counters (host/report/counters_json.h), on the pass whose
// counts tests/vgpu/test_stats.cpp works out by hand.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "host/report/counters_json.h"
#include "tests/support/known_pass.h"

using test_support::Known;
using test_support::known_pass;
using vgpu::Counters;

TEST_CASE("the JSON report parses and carries the frame totals and every program") {
  const Known k = known_pass(2, 8);
  const nlohmann::json j = nlohmann::json::parse(host::frame_counters_json(k.stats).dump(2));
  const Counters& t = k.stats.totals;
  CHECK(j.at("totals").at("passes").get<uint64_t>() == 1);
  CHECK(j.at("totals").at("fragments_shaded").get<uint64_t>() == 4096);
  CHECK(j.at("totals").at("texture_fetches").get<uint64_t>() == 12288);
  CHECK(j.at("totals").at("bytes_read").get<uint64_t>() == 196608);
  CHECK(j.at("totals").at("bytes_written").get<uint64_t>() == t.bytes_written);
  CHECK(j.at("totals").at("instructions").get<uint64_t>() == 20480);
  CHECK(j.at("totals").at("program_loads").get<uint64_t>() == 1);
  CHECK(j.at("totals").at("program_bytes").get<uint64_t>() == 80);
  CHECK(j.at("totals").at("host_ms").get<double>() == doctest::Approx(t.host_ms));
  REQUIRE(j.at("programs").size() == 1);
  const nlohmann::json& p = j.at("programs")[0];
  CHECK(p.at("name") == "add3");
  CHECK(p.at("paper_name") == "intersecciones");
  CHECK(p.at("static_instructions") == 5);
  CHECK(p.at("instructions").get<uint64_t>() == 20480);  // executed: static count x fragments
  CHECK(p.at("texture_fetches").get<uint64_t>() == 12288);
  // Compact form parses to the same document.
  CHECK(nlohmann::json::parse(host::frame_counters_json(k.stats).dump(-1)) == j);
}
