#include "mm/search/search.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "detail.hpp"

namespace mm {

Status SearchInput::validate() const {
  if (dims < 1 || dims > kMaxSearchDims) {
    return Error{"search input: feature dimension " + std::to_string(dims) + " is outside [1, " +
                 std::to_string(kMaxSearchDims) + "]"};
  }
  const size_t frames = searchable.size();
  if (features.size() != frames * static_cast<size_t>(dims)) {
    return Error{"search input: the feature matrix holds " + std::to_string(features.size()) +
                 " floats, expected frame_count * dims = " + std::to_string(frames) + " * " +
                 std::to_string(dims)};
  }
  if (frame_clip.size() != frames) {
    return Error{"search input: frame_clip holds " + std::to_string(frame_clip.size()) +
                 " entries, expected one per frame (" + std::to_string(frames) + ")"};
  }
  for (size_t f = 0; f < frames; ++f) {
    const int clip = frame_clip[f];
    if (clip < 0 || static_cast<size_t>(clip) >= clips.size()) {
      return Error{"search input: frame " + std::to_string(f) + " names clip " +
                   std::to_string(clip) + ", but there are " + std::to_string(clips.size())};
    }
    const SearchClip& range = clips[static_cast<size_t>(clip)];
    if (static_cast<int>(f) < range.start || static_cast<int>(f) >= range.end) {
      return Error{"search input: frame " + std::to_string(f) + " is outside the range [" +
                   std::to_string(range.start) + ", " + std::to_string(range.end) +
                   ") of its clip " + std::to_string(clip)};
    }
  }
  for (size_t i = 0; i < features.size(); ++i) {
    if (!std::isfinite(features[i])) {
      return Error{"search input: feature " + std::to_string(i % dims) + " of frame " +
                   std::to_string(i / dims) + " is not finite"};
    }
  }
  return Status::success();
}

std::span<const std::string_view> search_method_names() {
  static constexpr std::string_view names[] = {"brute-simd", "kdtree", "boxtree", "kdtree-eps"};
  return names;
}

Result<std::unique_ptr<Searcher>> make_searcher(std::string_view method, const SearchInput& input,
                                                const SearchOptions& options) {
  if (Status valid = input.validate(); !valid) return Error{valid.message()};
  if (method == "brute-simd") return search_detail::make_brute_simd(input);
  if (method == "kdtree") return search_detail::make_kdtree(input, options);
  if (method == "boxtree") return search_detail::make_boxtree(input, options);
  if (method == "kdtree-eps") return search_detail::make_kdtree_eps(input, options);
  std::string known;
  for (std::string_view name : search_method_names()) {
    known += known.empty() ? "" : ", ";
    known += name;
  }
  return Error{"unknown search method '" + std::string(method) + "' (known: " + known + ")"};
}

namespace search_detail {

size_t CandidateSet::memory_bytes() const {
  return rows.capacity() * sizeof(float) + row_frame.capacity() * sizeof(int) +
         row_tags.capacity() * sizeof(uint64_t) + frame_row.capacity() * sizeof(int) +
         frame_clip.capacity() * sizeof(int);
}

CandidateSet make_candidate_set(const SearchInput& input) {
  CandidateSet set;
  set.dims = input.dims;
  set.frame_count = input.frame_count();
  set.frame_clip.assign(input.frame_clip.begin(), input.frame_clip.end());
  set.frame_row.assign(static_cast<size_t>(set.frame_count), -1);
  const auto dims = static_cast<size_t>(input.dims);
  const auto searchable = static_cast<size_t>(std::count_if(
      input.searchable.begin(), input.searchable.end(), [](uint8_t s) { return s != 0; }));
  set.rows.reserve(searchable * dims);
  set.row_frame.reserve(searchable);
  set.row_tags.reserve(searchable);
  for (int f = 0; f < set.frame_count; ++f) {
    if (!input.searchable[static_cast<size_t>(f)]) continue;
    set.frame_row[static_cast<size_t>(f)] = set.row_count();
    set.row_frame.push_back(f);
    set.row_tags.push_back(
        input.clips[static_cast<size_t>(input.frame_clip[static_cast<size_t>(f)])].tags);
    const float* row = input.features.data() + static_cast<size_t>(f) * dims;
    set.rows.insert(set.rows.end(), row, row + dims);
  }
  return set;
}

QueryPlan plan_query(const CandidateSet& set, const float* query,
                     const SearchConstraints& constraints) {
  QueryPlan plan;
  plan.filter.row_tags = set.row_tags.data();
  plan.filter.row_frame = set.row_frame.data();
  plan.filter.row_count = set.row_count();
  plan.filter.include_tags = constraints.include_tags;
  plan.filter.exclude_tags = constraints.exclude_tags;
  plan.bound = std::numeric_limits<float>::infinity();
  const int current = constraints.current_frame;
  if (current < 0 || current >= set.frame_count) return plan;
  plan.filter.window_first = current - constraints.window_frames;
  plan.filter.window_last = current + constraints.window_frames;
  const int next = current + 1;
  if (next >= set.frame_count) return plan;
  if (set.frame_clip[static_cast<size_t>(next)] != set.frame_clip[static_cast<size_t>(current)]) {
    return plan;
  }
  const int row = set.frame_row[static_cast<size_t>(next)];
  if (row < 0 || !tags_pass(set.row_tags[static_cast<size_t>(row)], constraints.include_tags,
                            constraints.exclude_tags)) {
    return plan;
  }
  plan.continuation_row = row;
  plan.continuation_distance = search_kernels::squared_distance(query, set.row(row), set.dims);
  plan.bound = plan.continuation_distance - constraints.transition_cost;
  return plan;
}

SearchResult finish_query(const CandidateSet& set, const QueryPlan& plan, const float* query,
                          int best_row, const SearchConstraints& constraints) {
  SearchResult result;
  if (plan.continuation_row >= 0) {
    result.frame = set.row_frame[static_cast<size_t>(plan.continuation_row)];
    result.cost = plan.continuation_distance;
    result.continuation = true;
  }
  if (best_row >= 0) {
    const float cost = search_kernels::squared_distance(query, set.row(best_row), set.dims) +
                       constraints.transition_cost;
    if (cost < result.cost) {
      result.frame = set.row_frame[static_cast<size_t>(best_row)];
      result.cost = cost;
      result.continuation = false;
    }
  }
  return result;
}

}  // namespace search_detail

// ---------------------------------------------------------------------------------------------
// Batch runner: a fixed set of worker threads that each take queries from a shared counter.

struct SearchBatchRunner::State {
  int thread_count = 1;
  std::vector<std::thread> workers;
  std::mutex mutex;
  std::condition_variable wake;
  std::condition_variable done;
  // The job of the current run(), set under the mutex before the generation changes.
  const Searcher* searcher = nullptr;
  std::span<const float> queries;
  std::span<const SearchConstraints> constraints;
  std::span<SearchResult> results;
  std::atomic<int> next{0};
  int generation = 0;    // incremented by each run()
  int busy_workers = 0;  // workers still working on the current generation
  bool stopping = false;

  // Takes queries in small chunks until none are left.
  void work() {
    const size_t dims = static_cast<size_t>(searcher->dims());
    const int count = static_cast<int>(results.size());
    constexpr int kChunk = 4;
    for (;;) {
      const int first = next.fetch_add(kChunk, std::memory_order_relaxed);
      if (first >= count) return;
      const int last = std::min(count, first + kChunk);
      for (int i = first; i < last; ++i) {
        const SearchConstraints& c =
            constraints.size() == 1 ? constraints[0] : constraints[static_cast<size_t>(i)];
        results[static_cast<size_t>(i)] =
            searcher->search(queries.subspan(static_cast<size_t>(i) * dims, dims), c);
      }
    }
  }

  void worker_loop() {
    int seen = 0;
    for (;;) {
      {
        std::unique_lock lock(mutex);
        wake.wait(lock, [&] { return stopping || generation != seen; });
        if (stopping) return;
        seen = generation;
      }
      work();
      {
        std::lock_guard lock(mutex);
        if (--busy_workers == 0) done.notify_one();
      }
    }
  }
};

SearchBatchRunner::SearchBatchRunner(int thread_count) : state_(std::make_unique<State>()) {
  state_->thread_count = std::max(1, thread_count);
  for (int i = 1; i < state_->thread_count; ++i) {
    state_->workers.emplace_back([s = state_.get()] { s->worker_loop(); });
  }
}

SearchBatchRunner::~SearchBatchRunner() {
  {
    std::lock_guard lock(state_->mutex);
    state_->stopping = true;
  }
  state_->wake.notify_all();
  for (std::thread& worker : state_->workers) worker.join();
}

int SearchBatchRunner::thread_count() const {
  return state_->thread_count;
}

void SearchBatchRunner::run(const Searcher& searcher, std::span<const float> queries,
                            std::span<const SearchConstraints> constraints,
                            std::span<SearchResult> results) {
  const size_t dims = static_cast<size_t>(searcher.dims());
  MM_ASSERT(queries.size() == results.size() * dims);
  MM_ASSERT(constraints.size() == 1 || constraints.size() == results.size());
  (void)dims;
  if (results.empty()) return;
  State& s = *state_;
  {
    std::lock_guard lock(s.mutex);
    s.searcher = &searcher;
    s.queries = queries;
    s.constraints = constraints;
    s.results = results;
    s.next.store(0, std::memory_order_relaxed);
    s.busy_workers = static_cast<int>(s.workers.size());
    ++s.generation;
  }
  s.wake.notify_all();
  s.work();
  std::unique_lock lock(s.mutex);
  s.done.wait(lock, [&] { return s.busy_workers == 0; });
}

}  // namespace mm
