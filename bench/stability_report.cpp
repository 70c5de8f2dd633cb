// Runs every stability case (tests/trace/stability_cases.h) through the stream tracer at fp32,
// fp24 and fp16 and prints a markdown table: case x precision -> "pass" or
// "N of M pixels wrong (hit id), K unfinished rays". scripts/docs/stability.sh writes it to
// docs/studies/stability.md.
#include <cstdio>
#include <string>

#include "../tests/trace/stability_cases.h"

int main() {
  const auto all = stability::cases();
  const std::pair<vgpu::Format, const char*> precisions[] = {
      {vgpu::Format::fp32, "fp32"}, {vgpu::Format::fp24, "fp24"}, {vgpu::Format::fp16, "fp16"}};
  std::printf("| case | probes | pixels checked |");
  for (auto& p : precisions) std::printf(" %s |", p.second);
  std::printf("\n|---|---|---|");
  for (size_t i = 0; i < std::size(precisions); ++i) std::printf("---|");
  std::printf("\n");
  for (const auto& c : all) {
    int checked = 0;
    for (int e : c.expected) checked += e != stability::kDontCare;
    std::printf("| %s | %s | %d of %zu |", c.name.c_str(), c.probe.c_str(), checked,
                c.expected.size());
    for (auto& p : precisions) {
      const stability::Outcome o = stability::run(c, p.first);
      std::string cell;
      if (!o.error.empty()) {
        cell = "refused: " + o.error;
      } else if (o.wrong == 0 && o.colour_wrong == 0 && o.unfinished == 0) {
        cell = "pass";
      } else {
        cell =
            std::to_string(o.wrong) + " of " + std::to_string(o.checked) + " pixels wrong (hit id)";
        if (c.dominant_channel >= 0)
          cell += ", " + std::to_string(o.colour_wrong) + " wrong colour";
        cell += ", " + std::to_string(o.unfinished) + " unfinished rays";
      }
      std::printf(" %s |", cell.c_str());
    }
    std::printf("\n");
    std::fflush(stdout);
  }
  return 0;
}
