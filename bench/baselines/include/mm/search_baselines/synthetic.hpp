#pragma once
// Synthetic search data for the search tests and benchmarks that must run without the
// motion-capture files (not part of the library's API): clips of smooth, curve-like feature rows
// (locomotion-like cycles with drift) and a dense cluster of low-variance "standing" clips, the
// hard case for search trees.

#include <cstdint>
#include <span>
#include <vector>

#include "mm/search/search.hpp"

namespace mm {

// What to generate.
struct SyntheticSearchSpec {
  int clip_count = 200;            // clips in total
  int min_clip_frames = 60;        // shortest clip
  int max_clip_frames = 300;       // longest clip
  int dims = 27;                   // feature columns
  float standing_fraction = 0.5f;  // share of clips that are low-variance standing clips
  int excluded_tail_frames = 30;   // last frames of each clip that are not searchable
  int tag_count = 4;               // tags 1..tag_count-1 are random; tag 0 marks standing clips
  uint64_t seed = 1;               // the generator is deterministic for a given seed
};

// Generated arrays, laid out like a database's search arrays.
struct SyntheticSearchData {
  int dims = 0;
  std::vector<float> features;      // frame_count * dims
  std::vector<uint8_t> searchable;  // per frame
  std::vector<int> frame_clip;      // per frame
  std::vector<SearchClip> clips;    // ranges and tag masks

  int frame_count() const { return static_cast<int>(searchable.size()); }
  // Views for make_searcher() (valid while this object lives).
  SearchInput input() const;
};

// Generates data following `spec` (sizes are clamped to sane minimums).
SyntheticSearchData make_synthetic_search_data(const SyntheticSearchSpec& spec);

// Benchmark and test queries: searchable frames drawn uniformly, plus Gaussian noise.
struct NoisyQueries {
  int dims = 0;
  std::vector<float> features;     // count * dims: the source row plus noise
  std::vector<int> source_frames;  // per query: the frame it was drawn from

  int count() const { return static_cast<int>(source_frames.size()); }
  // The features of query i.
  std::span<const float> query(int i) const {
    return {features.data() + static_cast<size_t>(i) * dims, static_cast<size_t>(dims)};
  }
};

// `count` queries: uniformly drawn searchable frames of `input` plus Gaussian noise of standard
// deviation `noise` (normalized units) per column; deterministic for a given seed. Empty when no
// frame is searchable.
NoisyQueries make_noisy_queries(const SearchInput& input, int count, float noise, uint64_t seed);

}  // namespace mm
