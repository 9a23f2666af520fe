// `brute`: the rules applied exactly as they are written, frame by frame.

#include <cassert>

#include "detail.hpp"
#include "factories.hpp"

namespace mm::search_baselines {

using search_detail::tags_pass;

namespace {

// The reference: every frame is checked against the rules exactly as they are written, with
// only an early exit per row once its partial distance cannot win (which never changes the
// answer, since partial sums only grow).
class BruteSearcher final : public Searcher {
 public:
  explicit BruteSearcher(const SearchInput& input)
      : dims_(input.dims),
        features_(input.features.begin(), input.features.end()),
        searchable_(input.searchable.begin(), input.searchable.end()),
        frame_clip_(input.frame_clip.begin(), input.frame_clip.end()) {
    clip_tags_.reserve(input.clips.size());
    for (const SearchClip& clip : input.clips) clip_tags_.push_back(clip.tags);
  }

  std::string_view method() const override { return "brute"; }
  int dims() const override { return dims_; }
  bool exact() const override { return true; }
  size_t memory_bytes() const override {
    return features_.capacity() * sizeof(float) + searchable_.capacity() +
           frame_clip_.capacity() * sizeof(int) + clip_tags_.capacity() * sizeof(uint64_t);
  }

  const float* row(int frame) const {
    return features_.data() + static_cast<size_t>(frame) * dims_;
  }

  SearchResult search(std::span<const float> query,
                      const SearchConstraints& constraints) const override {
    assert(static_cast<int>(query.size()) == dims_);
    const int frame_count = static_cast<int>(searchable_.size());
    const int current = constraints.current_frame;
    const bool playing = current >= 0 && current < frame_count;
    SearchResult best;
    // The continuation first: every other candidate then has to be strictly cheaper, which is
    // how the continuation wins ties.
    const int next = current + 1;
    if (playing && next < frame_count && searchable_[static_cast<size_t>(next)] &&
        frame_clip_[static_cast<size_t>(next)] == frame_clip_[static_cast<size_t>(current)] &&
        tags_pass(clip_tags_[static_cast<size_t>(frame_clip_[static_cast<size_t>(next)])],
                  constraints.include_tags, constraints.exclude_tags)) {
      best.frame = next;
      best.cost = search_kernels::squared_distance(query.data(), row(next), dims_);
      best.continuation = true;
    }
    for (int f = 0; f < frame_count; ++f) {
      if (!searchable_[static_cast<size_t>(f)]) continue;
      if (best.continuation && f == best.frame) continue;
      if (!tags_pass(clip_tags_[static_cast<size_t>(frame_clip_[static_cast<size_t>(f)])],
                     constraints.include_tags, constraints.exclude_tags)) {
        continue;
      }
      if (playing && f >= current - constraints.window_frames &&
          f <= current + constraints.window_frames) {
        continue;
      }
      // Early exit per row: once the partial sum reaches the bound the row cannot win.
      const float bound = best.cost - constraints.transition_cost;
      const float distance =
          search_kernels::squared_distance_bounded(query.data(), row(f), dims_, bound);
      if (distance < bound && distance + constraints.transition_cost < best.cost) {
        best.frame = f;
        best.cost = distance + constraints.transition_cost;
        best.continuation = false;
      }
    }
    return best;
  }

 private:
  int dims_;
  std::vector<float> features_;
  std::vector<uint8_t> searchable_;
  std::vector<int> frame_clip_;
  std::vector<uint64_t> clip_tags_;
};

}  // namespace

Result<std::unique_ptr<Searcher>> make_brute(const SearchInput& input) {
  return std::unique_ptr<Searcher>(std::make_unique<BruteSearcher>(input));
}

}  // namespace mm::search_baselines
