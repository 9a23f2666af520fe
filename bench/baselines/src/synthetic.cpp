#include "mm/search_baselines/synthetic.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace mm {

SearchInput SyntheticSearchData::input() const {
  SearchInput view;
  view.features = features;
  view.dims = dims;
  view.searchable = searchable;
  view.frame_clip = frame_clip;
  view.clips = clips;
  return view;
}

SyntheticSearchData make_synthetic_search_data(const SyntheticSearchSpec& spec) {
  SyntheticSearchData data;
  data.dims = std::clamp(spec.dims, 1, kMaxSearchDims);
  const int clip_count = std::max(1, spec.clip_count);
  const int min_frames = std::max(1, spec.min_clip_frames);
  const int max_frames = std::max(min_frames, spec.max_clip_frames);
  const int tag_count = std::clamp(spec.tag_count, 1, 64);
  const auto dims = static_cast<size_t>(data.dims);
  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::normal_distribution<float> gauss(0.0f, 1.0f);

  // Every clip shares one standing pose, so standing clips form one tight cluster.
  std::vector<float> standing_center(dims);
  for (float& v : standing_center) v = 0.5f * gauss(rng);

  for (int c = 0; c < clip_count; ++c) {
    SearchClip clip;
    clip.start = data.frame_count();
    const int frames =
        min_frames + static_cast<int>(unit(rng) * static_cast<float>(max_frames - min_frames + 1));
    clip.end = clip.start + std::min(frames, max_frames);
    const bool standing = unit(rng) < spec.standing_fraction;
    if (standing) clip.tags |= 1;
    for (int t = 1; t < tag_count; ++t) {
      if (unit(rng) < 0.5f) clip.tags |= uint64_t{1} << t;
    }
    // Per column: a base level, a cycle (gait-like, about one second at 30 frames per second)
    // and a slow random walk. Standing clips move two orders of magnitude less.
    const float scale = standing ? 0.03f : 1.0f;
    std::vector<float> base(dims), amplitude(dims), phase(dims), frequency(dims), drift(dims);
    for (size_t d = 0; d < dims; ++d) {
      base[d] = standing ? standing_center[d] + 0.05f * gauss(rng) : gauss(rng);
      amplitude[d] = scale * (0.2f + 0.8f * unit(rng));
      phase[d] = 6.2831853f * unit(rng);
      frequency[d] = 6.2831853f / (20.0f + 20.0f * unit(rng));
      drift[d] = 0.0f;
    }
    for (int f = clip.start; f < clip.end; ++f) {
      const auto t = static_cast<float>(f - clip.start);
      for (size_t d = 0; d < dims; ++d) {
        drift[d] += scale * 0.05f * gauss(rng);
        drift[d] *= 0.98f;  // keeps the walk bounded
        data.features.push_back(base[d] + amplitude[d] * std::sin(frequency[d] * t + phase[d]) +
                                drift[d]);
      }
      data.searchable.push_back(f < clip.end - spec.excluded_tail_frames ? 1 : 0);
      data.frame_clip.push_back(c);
    }
    data.clips.push_back(std::move(clip));
  }
  return data;
}

NoisyQueries make_noisy_queries(const SearchInput& input, int count, float noise, uint64_t seed) {
  NoisyQueries queries;
  queries.dims = input.dims;
  std::vector<int> frames;
  for (int f = 0; f < input.frame_count(); ++f) {
    if (input.searchable[static_cast<size_t>(f)]) frames.push_back(f);
  }
  if (frames.empty() || count <= 0) return queries;
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> gauss(0.0f, 1.0f);
  const auto dims = static_cast<size_t>(input.dims);
  queries.features.reserve(static_cast<size_t>(count) * dims);
  for (int i = 0; i < count; ++i) {
    const int frame = frames[static_cast<size_t>(rng() % frames.size())];
    queries.source_frames.push_back(frame);
    const float* row = input.features.data() + static_cast<size_t>(frame) * dims;
    for (size_t d = 0; d < dims; ++d) queries.features.push_back(row[d] + noise * gauss(rng));
  }
  return queries;
}

}  // namespace mm
