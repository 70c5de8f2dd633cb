// The command line's animation options (issue 23): --time T, --frames A:B:N and the '#' frame
// numbers of output paths, parsed and checked before any work.
#pragma once

#include <string>
#include <vector>

namespace cli {

// Most frames one --frames asks for.
inline constexpr int kMaxFrames = 100000;

// --time's value: seconds from the animation's start, a finite decimal number of 0 or more
// (glTF key times are never negative). Empty when good, else the problem.
std::string time_problem(const std::string& text);
double parse_time(const std::string& text);  // a text time_problem() accepted

// --frames A:B:N: N frames evenly from A to B seconds, both ends included (N = 1: A alone);
// A <= B, N from 1 to kMaxFrames. --frames N, without bounds: N frames over the played
// animations' span (from the first key time of any of them to the last), which only the file
// knows: `bounded` is false and a, b are filled in once it is read.
struct FrameRange {
  double a = 0, b = 0;
  int n = 1;
  bool bounded = true;
};
// Empty when good, else the problem; `range` is set when good.
std::string frames_problem(const std::string& text, FrameRange& range);
// The frames' times in seconds: A + (B - A) i / (N - 1), i = 0 .. N - 1, the last exactly B.
std::vector<double> frame_times(const FrameRange& range);

// Output paths with a frame number, as Blender writes them: the last run of '#' characters in
// the file name (not the directories) becomes the frame number, zero-padded to the run's length
// (frame_####.png, frame 7: frame_0007.png; numbers too long for the run are written whole).
bool has_frame_number(const std::string& path);
std::string frame_path(const std::string& pattern, int number);

}  // namespace cli
