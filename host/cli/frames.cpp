// The animation options' parsing (see frames.h).
#include "host/cli/frames.h"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace cli {
namespace {

// A whole decimal number as from_chars reads it (no sign, spaces or suffix), finite; or NaN.
double number(const std::string& text) {
  double v = NAN;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (ec != std::errc() || ptr != end || text.empty()) return NAN;
  return std::isfinite(v) ? v : NAN;
}

// The file name's part of a path: after the last '/'.
size_t name_start(const std::string& path) {
  const size_t slash = path.rfind('/');
  return slash == std::string::npos ? 0 : slash + 1;
}

}  // namespace

std::string time_problem(const std::string& text) {
  const double t = number(text);
  if (std::isnan(t))
    return "expected seconds, a number of 0 or more (e.g. 1.5), got '" + text + "'";
  if (t < 0) return text + ": times are seconds from the animation's start, 0 or more";
  return {};
}

double parse_time(const std::string& text) {
  return number(text);
}

std::string frames_problem(const std::string& text, FrameRange& range) {
  const size_t c1 = text.find(':'), c2 = c1 == std::string::npos ? c1 : text.find(':', c1 + 1);
  const std::string expected =
      "expected A:B:N (N frames evenly from A to B seconds, e.g. 0:2:25) or N (N frames over "
      "the animations' keys, e.g. 25), got '" +
      text + "'";
  const bool bounded = c1 != std::string::npos;  // else the count alone
  if (bounded && (c2 == std::string::npos || text.find(':', c2 + 1) != std::string::npos))
    return expected;
  const std::string sa = bounded ? text.substr(0, c1) : "0",
                    sb = bounded ? text.substr(c1 + 1, c2 - c1 - 1) : "0",
                    sn = bounded ? text.substr(c2 + 1) : text;
  const double a = number(sa), b = number(sb);
  int n = 0;
  const auto [ptr, ec] = std::from_chars(sn.data(), sn.data() + sn.size(), n);
  if (std::isnan(a) || std::isnan(b) || ec == std::errc::invalid_argument ||
      ptr != sn.data() + sn.size() || sn.empty())
    return expected;
  if (a < 0 || b < 0) return text + ": times are seconds from the animation's start, 0 or more";
  if (a > b) return text + ": the first time (" + sa + " s) is after the last (" + sb + " s)";
  if (ec == std::errc::result_out_of_range || n < 1 || n > kMaxFrames)
    return text + ": the frame count must be 1 to " + std::to_string(kMaxFrames) + ", got " + sn;
  range = {a, b, n, bounded};
  return {};
}

std::vector<double> frame_times(const FrameRange& r) {
  std::vector<double> t(size_t(r.n));
  for (int i = 0; i < r.n; ++i)
    t[size_t(i)] = i == 0         ? r.a
                   : i == r.n - 1 ? r.b
                                  : r.a + (r.b - r.a) * double(i) / double(r.n - 1);
  return t;
}

bool has_frame_number(const std::string& path) {
  return path.find('#', name_start(path)) != std::string::npos;
}

std::string frame_path(const std::string& pattern, int number) {
  const size_t start = name_start(pattern);
  const size_t last = pattern.rfind('#');
  if (last == std::string::npos || last < start) return pattern;
  size_t first = last;
  while (first > start && pattern[first - 1] == '#') --first;
  char digits[32];
  std::snprintf(digits, sizeof digits, "%0*d", int(last - first + 1), number);
  return pattern.substr(0, first) + digits + pattern.substr(last + 1);
}

}  // namespace cli
