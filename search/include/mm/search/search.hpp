#pragma once
// Motion-matching search: given a query vector in the normalized feature space and the
// constraints of the character that asks, find the candidate frame of lowest cost.
//
// The rules every method implements (and the tests check against a plain reference scan):
// - Candidates are the frames marked searchable when the database was built (every feature
//   time of the frame lies inside its own clip), whose clip passes the tag filter: the clip
//   must carry every tag of `include_tags` and none of `exclude_tags`.
// - The continuation candidate is current_frame + 1 when it exists, lies in the same clip as
//   current_frame, is searchable and passes the tag filter. Its cost is its plain squared
//   distance to the query; it is exempt from the window.
// - Every other candidate outside [current_frame - window_frames, current_frame + window_frames]
//   costs its squared distance + transition_cost. Frames inside that window are skipped.
// - With current_frame < 0 nothing plays: no continuation, no window, and every candidate
//   pays the transition cost.
// - The result is the candidate of lowest cost. On equal cost the continuation wins; between
//   other candidates of equal cost any may be returned (duplicate takes exist), but exact
//   methods always return the lowest cost.
// The distance is the plain squared Euclidean distance between the query and a row of the
// normalized feature matrix (the weights are folded into the normalization).

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mm/runtime/result.hpp"

namespace mm {

// The largest feature dimension a searcher accepts: hot paths keep per-query buffers of this
// size on the stack so that search() never allocates.
inline constexpr int kMaxSearchDims = 256;

// One clip as the search sees it: frames [start, end) and the mask of its tags. Continuations
// never cross a clip boundary, and tag filters test the clip's mask.
struct SearchClip {
  int start = 0;      // first frame of the clip
  int end = 0;        // one past its last frame
  uint64_t tags = 0;  // bit i set when the clip carries tag i
};

// What a searcher is built from: views of the database's arrays. Searchers copy what they keep,
// so the views only need to live while the searcher is being made.
struct SearchInput {
  std::span<const float> features;      // frame_count * dims floats, row-major, normalized
  int dims = 0;                         // columns of the feature matrix
  std::span<const uint8_t> searchable;  // frame_count flags: 1 when the frame may be matched
  std::span<const int> frame_clip;      // frame_count clip indices
  std::span<const SearchClip> clips;    // clip ranges and their tag masks

  // Number of frames (rows of the feature matrix).
  int frame_count() const { return static_cast<int>(searchable.size()); }
  // Sizes agree, dims is in [1, kMaxSearchDims], features are finite, every frame's clip
  // exists and its range contains the frame.
  Status validate() const;
};

// Per-query constraints (see the rules at the top of this file).
struct SearchConstraints {
  int current_frame = -1;        // the frame playing now, or -1 when nothing plays
  int window_frames = 0;         // >= 0: frames within this distance of current_frame are skipped
  float transition_cost = 0.0f;  // >= 0: added to every candidate except the continuation
  uint64_t include_tags = 0;     // a candidate's clip must carry all of these tags
  uint64_t exclude_tags = 0;     // a candidate's clip must carry none of these tags
};

// The answer to one query.
struct SearchResult {
  int frame = -1;  // the chosen database frame, -1 when no frame is a candidate
  float cost = std::numeric_limits<float>::infinity();  // its cost under the rules above
  bool continuation = false;  // true when the chosen frame is the continuation candidate
};

// Tunables of the search structures; every method reads the fields it needs.
struct SearchOptions {
  // Rows per leaf of the FLANN exact KD-tree (`kdtree`, `kdtree-eps`). 32 rather than 16:
  // larger leaves mean fewer levels to backtrack, which pays on the many-style databases and
  // is neutral on a single style (figures in docs/search.md).
  int kdtree_leaf_size = 32;
  // Rows per leaf of the box tree (`boxtree`): a positive multiple of 8 (one SIMD block).
  int boxtree_leaf_size = 64;
  // The tree methods first group the rows by k-means, about this many rows per group, and keep
  // apart the dense groups (total variance under 1 % of the database's, such as the standing
  // gestures), merging all others into one: one tree per group, each in the group's own
  // principal axes. A query visits groups nearest first and skips those whose bounding box is
  // farther than the best cost found. Without a dense cluster this is a single tree; 0 always
  // builds a single tree.
  int kdtree_group_rows = 4096;   // rows per group of `kdtree` and `kdtree-eps`
  int boxtree_group_rows = 4096;  // rows per group of `boxtree`
  // `kdtree` and `kdtree-eps` also build one index per tag class (rows whose clips carry
  // exactly the same tags), searched when a query's tag filter leaves less than a quarter of
  // the rows.
  bool tag_class_indices = true;
  // Build the trees over the principal axes of the rows instead of the raw columns. Results
  // stay exact: rows are decided by their unrotated distance.
  bool principal_axes = true;
  // eps of `kdtree-eps`: the distance found is within (1 + eps) times the best. 3 because the
  // bound is loose: in practice nearly every answer is still exact, at a clearly lower median
  // than eps 2 (figures in docs/search.md).
  float kdtree_eps = 3.0f;
  // Threads that build the trees' groups in parallel (`kdtree`, `kdtree-eps`); 0: every core.
  int build_threads = 0;
};

// One search structure over one database. Instances are immutable after creation: search()
// is const, thread-safe, and does not allocate (methods built on FLANN document where FLANN
// allocates internally).
class Searcher {
 public:
  virtual ~Searcher() = default;
  // The method's name, as accepted by make_searcher().
  virtual std::string_view method() const = 0;
  // The feature dimension the searcher was built for (the query's length).
  virtual int dims() const = 0;
  // True when the method returns the exact lowest cost (all but `kdtree-eps` here).
  virtual bool exact() const = 0;
  // Bytes the searcher owns (its copies of the rows, the index, the masks).
  virtual size_t memory_bytes() const = 0;
  // The best candidate for `query` (dims() normalized floats) under `constraints`.
  virtual SearchResult search(std::span<const float> query,
                              const SearchConstraints& constraints) const = 0;
};

// The method names make_searcher() accepts, the reference first:
// - brute-simd: every candidate row, in blocks of 8 rows scanned with AVX2 (or portable vector
//   code): the brute-force reference, exact and with no structure to trust.
// - kdtree: FLANN's exact single KD-tree (KDTreeSingleIndex) in principal axes, one per dense
//   k-means group, plus one per tag class for selective tag filters.
// - boxtree: k-d trees with a tight bounding box per node and SIMD-scanned leaves, in principal
//   axes, one per dense group: the exact search for every case, including the hard ones.
// - kdtree-eps: `kdtree` with FLANN's eps: a branch is skipped once its lower bound times
//   (1 + eps) reaches the best distance so far, so the distance found is at most (1 + eps) times
//   the best one; not exact, but bounded, and cheaper than randomized trees with a check budget
//   (each of their checks descends the tree anew).
// Baselines that only serve comparison (a plain scan, bounding boxes over consecutive rows,
// FLANN's randomized trees) live with the benchmarks, in bench/baselines/.
std::span<const std::string_view> search_method_names();

// Builds the named search structure over `input`; fails on an unknown name, invalid input or
// invalid options, with a message naming what is wrong.
Result<std::unique_ptr<Searcher>> make_searcher(std::string_view method, const SearchInput& input,
                                                const SearchOptions& options = {});

// Runs many queries (one per character) through one searcher on several threads. The worker
// threads are started once, in the constructor; run() does not allocate.
class SearchBatchRunner {
 public:
  // thread_count >= 1 threads in total, the calling thread included.
  explicit SearchBatchRunner(int thread_count = 2);
  ~SearchBatchRunner();
  SearchBatchRunner(const SearchBatchRunner&) = delete;
  SearchBatchRunner& operator=(const SearchBatchRunner&) = delete;

  // Threads used by run(), the caller included.
  int thread_count() const;
  // results[i] = searcher.search(queries[i * dims .. (i + 1) * dims), constraints[i]), where
  // constraints holds either one entry per query or a single entry shared by all.
  void run(const Searcher& searcher, std::span<const float> queries,
           std::span<const SearchConstraints> constraints, std::span<SearchResult> results);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace mm
