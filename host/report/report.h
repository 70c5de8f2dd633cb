// One frame of the stream tracer as data a person can look at: a PassObserver that records every
// pass (kernel, counts, useful/idle/masked fragments, query results), per-pixel costs, the work
// masks (pixel history and the ray wavefront) and SIMD occupancy; and the writers that turn it
// into a self-contained HTML report (page template in host/report/), a per-pass CSV, and a diff
// of two --stats-json files.
#pragma once

#include <array>
#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "host/trace/stream/stream_tracer.h"

namespace host {

// Occupancy histogram bins: active lanes of an 8x4 tile (0..32, one bin each) and of a 32x32
// tile (bin 0: none, bin b: 32(b-1)+1 .. 32b lanes).
inline constexpr int kOccupancyBins = 33;
// The report keeps every pass's state for the pixels on this grid (every 8th pixel in x and y):
// 1024 pixels at 256x256, about 1.6 MB of the report for bunny-refl.
inline constexpr int kHistoryStride = 8;
// The report keeps every distinct work mask (thousands per frame, a bit per pixel each): past
// 512x512 pixels that outgrows a browser tab, so the CLI refuses it.
inline constexpr int64_t kReportMaxPixels = 512 * 512;

class FrameRecorder final : public PassObserver {
 public:
  struct Pass {
    std::string program, paper_name, target;
    int channels = 0;         // of the target: floats of state per fragment
    int iteration = 0;        // 1-based; 0 before the first iteration (primary rays)
    int trace = -1;           // index into traces(); -1 outside a trace
    bool prints = true;       // its output is state (a counting pass only counts)
    vgpu::Counters counters;  // the pass itself (counters.passes == 1)
    // Counted around the pass but not by it: program loads and clears before it, the query
    // read-back after it. Pass counters plus these, summed over the frame, are the totals.
    vgpu::Counters before, after;
    uint64_t useful = 0;    // shaded fragments with work to do
    uint64_t idle = 0;      // shaded fragments with nothing to do (ray finished, no triangle left)
    int64_t query = -1;     // occlusion-query result, for a counting pass
    int work_mask = -1;     // mask id (masks()) of the fragments with work; -1: every fragment
    int written_mask = -1;  // mask id of the stencil a counting pass wrote; -1: none
  };
  struct Trace {
    TraceKind kind;
    int iteration = 0;
    int first_pass = 0;  // index of its first pass
    int steps = 0;       // traversal passes it ran
  };
  struct Occupancy {
    std::array<uint64_t, kOccupancyBins> tile8x4{}, tile32x32{};
  };

  // history_stride: every pixel at (x, y) with x and y multiples of it keeps its state after
  // every pass (0: none); `extra` pixels too. masks: the run models --masks on (idle fragments
  // are masked, not shaded). per_pixel off: only the per-pass records (the CSV), no masks, maps,
  // wavefront or history, so memory does not grow with passes times pixels.
  FrameRecorder(int width, int height, bool masks, int history_stride = kHistoryStride,
                std::vector<glm::ivec2> extra = {}, bool per_pixel = true);

  void iteration(int iteration) override;
  void trace_begin(TraceKind kind) override;
  void trace_end() override;
  void pass_begin(const vgpu::Stencil* work) override;
  void pass(const PassObserver::Pass& p) override;
  void query(uint64_t result, const vgpu::Stencil* written, const vgpu::FrameStats& s) override;
  // Closes the frame: what the statistics counted after the last pass lands in tail().
  void finish(const vgpu::FrameStats& stats);

  int width() const { return w_; }
  int height() const { return h_; }
  bool masks_on() const { return masks_; }
  const std::vector<Pass>& passes() const { return passes_; }
  const std::vector<Trace>& traces() const { return traces_; }
  const vgpu::Counters& tail() const { return tail_; }
  // Distinct work masks in order of first use, one bit per pixel (row-major, bit i of byte i/8).
  const std::vector<std::vector<uint8_t>>& masks() const { return masks_bits_; }
  // Per pixel (row-major): traversal passes with work (voxels stepped), intersection passes
  // with work (triangles tested), passes with a work mask where it had nothing to do.
  const std::vector<uint32_t>& voxel_steps() const { return voxels_; }
  const std::vector<uint32_t>& triangle_tests() const { return tests_; }
  const std::vector<uint32_t>& idle_passes() const { return idle_; }
  // Per pixel (row-major): iterations its fragments ran in looping programs' loops (each a
  // voxel step or node visit, a triangle test or both: --kernels looping).
  const std::vector<uint32_t>& loop_iterations() const { return loops_; }
  // Per trace and pixel: voxels stepped in that trace (walking after step k: steps > k).
  const std::vector<std::vector<uint16_t>>& wavefront() const { return wave_; }
  // Per kernel (in order of first use): active lanes per batch.
  const std::vector<std::pair<std::string, Occupancy>>& occupancy() const { return occ_; }
  // Pixels whose state is kept, and per pixel the floats of every pass it took part in that
  // prints state, in pass order (Pass::channels each).
  const std::vector<glm::ivec2>& history_pixels() const { return hist_px_; }
  const std::vector<std::vector<float>>& history_states() const { return hist_; }
  int history_stride() const { return stride_; }

 private:
  int store_mask(const vgpu::Stencil& s);
  Occupancy& occupancy_of(const std::string& program);

  int w_, h_;
  bool masks_;
  int stride_;
  int iteration_ = 0;
  int trace_ = -1;
  std::vector<Pass> passes_;
  std::vector<Trace> traces_;
  vgpu::Counters last_totals_, tail_;
  std::vector<std::vector<uint8_t>> masks_bits_;
  std::vector<uint8_t> packed_, active_;  // scratch
  std::vector<int> tile8_, tile32_;       // scratch: active lanes per tile column
  // The last masks stored, byte per pixel, for a quick match: {id, bytes}.
  std::array<std::pair<int, std::vector<uint8_t>>, 4> recent_{
      {{-1, {}}, {-1, {}}, {-1, {}}, {-1, {}}}};
  bool per_pixel_;
  bool has_work_ = false;      // the coming pass has a work mask (pass_begin)
  int work_id_ = -1;           // its id, when masks are kept
  std::vector<uint8_t> work_;  // and its bytes, one per pixel
  std::vector<uint32_t> voxels_, tests_, idle_, loops_;
  std::vector<std::vector<uint16_t>> wave_;
  std::vector<std::pair<std::string, Occupancy>> occ_;
  std::vector<glm::ivec2> hist_px_;
  std::vector<std::vector<float>> hist_;
};

// The counters of `a` minus those of `b`, field by field (host_ms too).
vgpu::Counters minus(const vgpu::Counters& a, const vgpu::Counters& b);

// Writes the HTML report: the image and AOVs from `result`, everything recorded, `run` (the
// --stats-json document, shown as the run's settings and the kernel table). Written under a
// temporary name and renamed, so a failure leaves nothing. Throws host::InputError.
void write_report(const std::string& path, const FrameRecorder& rec, const RenderResult& result,
                  const nlohmann::ordered_json& run);

// One row per pass: index, kernel, paper name, iteration, fragments launched / shaded / idle /
// masked / discarded, fetches, bytes read and written, query result. Same writing rules.
void write_stats_csv(const std::string& path, const FrameRecorder& rec);

// Two --stats-json files side by side, per kernel and in total: A, B, B - A and B / A.
// Throws host::InputError naming the file that cannot be read or is not such a file.
std::string diff_stats(const std::string& a_path, const std::string& b_path);

}  // namespace host
