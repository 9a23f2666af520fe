// `boxtree`: exact search in a forest of k-d trees whose every node keeps the tight bounding box
// of its rows, with leaves of a few blocks of 8 rows scanned by the vector kernel.
//
// Why not only FLANN's single KD-tree: FLANN bounds a branch by the distance to the cutting
// planes on its path (and to the root box), so for a noisy query near a dense, low-variance
// cluster (the standing gestures) the bound misses the query's offset in every dimension the
// path did not cut, and the search visits most of the cluster row by row. A tight box per node
// bounds the distance in all dimensions at once, so whole subtrees are skipped, and what cannot
// be skipped is scanned 8 rows per instruction instead of one.
//
// Why a forest: the rows are first grouped by k-means, and every group gets its own tree in its
// own principal axes. The standing gestures vary in a few directions of their own, which the
// axes of the whole database (dominated by locomotion) do not follow; in the group's own axes
// its boxes are thin in every other direction, so the query's offset from the cluster counts in
// every bound and the trees prune inside the cluster too. Groups are visited nearest first by
// the distance to their bounding box in the original space, and skipped once that distance
// reaches the best cost found.
//
// In a group's principal axes the leading columns carry nearly all of its spread, so node boxes
// keep only the first 16 columns (two vectors, half the memory to read) and the group's root box
// bounds the remaining columns once per query: every row lies inside the root box, so its
// distance over those columns is at least the root box's. For the same reason leaves are scanned
// in stages (search_kernels::scan_blocks_staged_avx2): a group of blocks whose rows are all
// beyond the bound after 8 or 16 columns is left there.
//
// Rows found in a rotated space are decided by their canonical distance (ExactRanker), so the
// answer is exactly brute force's. Per node, the OR and AND of its rows' tags skip subtrees that
// cannot pass a tag filter; the window and the continuation are handled by the row filter and
// the starting bound.

#include <algorithm>
#include <cstring>
#include <numeric>

#include "detail.hpp"

namespace mm::search_detail {

namespace {

using search_kernels::kBlockRows;

struct Node {
  int first_block = 0;  // the node's rows are blocks [first_block, last_block)
  int last_block = 0;
  int first_child = -1;  // -1 for a leaf; children are first_child and first_child + 1
};

// Everything a traversal reads, as plain views.
struct TreeView {
  const Node* nodes;
  const float* boxes;  // per node: box_dims lows, then box_dims highs
  const uint64_t* node_tags_or;
  const uint64_t* node_tags_and;
  const float* blocks;
  int dims;
  int box_dims;  // leading columns the node boxes cover (a multiple of 8)
  float base;    // lower bound of every row's distance over the other columns (from the root box)
  search_kernels::ScanBlocksFn scan;
};

constexpr int kMaxTreeDepth = 60;

// Columns the node boxes cover when the tree is in principal axes (two vectors).
constexpr int kRotatedBoxDims = 16;

// Depth-first, nearer child first; a subtree is entered only while its box is closer than the
// best so far. `best` carries the threshold in and the answer out. A subtree pushed for later
// has its children's boxes (or its first rows, for a leaf) prefetched: a traversal is a chain of
// dependent reads, and each one that misses the caches stalls the traversal (docs/search.md).
__attribute__((always_inline)) inline void traverse(const TreeView& tree, const float* query,
                                                    const search_kernels::RowFilter& filter,
                                                    bool tag_filter,
                                                    search_kernels::ScanBest& best) {
  struct Pending {
    int node;
    float distance;
  };
  Pending stack[2 * kMaxTreeDepth + 2];
  int size = 0;
  const size_t box_stride = 2 * static_cast<size_t>(tree.box_dims);
  const size_t block_floats = static_cast<size_t>(tree.dims) * kBlockRows;
  auto node_box_distance = [&](int node) {
    if (tag_filter && ((tree.node_tags_or[node] & filter.include_tags) != filter.include_tags ||
                       (tree.node_tags_and[node] & filter.exclude_tags) != 0)) {
      return std::numeric_limits<float>::infinity();
    }
    const float* box = tree.boxes + static_cast<size_t>(node) * box_stride;
    return tree.base + box_distance(query, box, box + tree.box_dims, tree.box_dims);
  };
  auto push = [&](int node, float distance) {
    const Node& n = tree.nodes[node];
    if (n.first_child >= 0) {
      const char* boxes = reinterpret_cast<const char*>(
          tree.boxes + static_cast<size_t>(n.first_child) * box_stride);
      for (size_t offset = 0; offset < 2 * box_stride * sizeof(float); offset += 64) {
        __builtin_prefetch(boxes + offset);
      }
    } else {
      const char* rows = reinterpret_cast<const char*>(
          tree.blocks + static_cast<size_t>(n.first_block) * block_floats);
      for (size_t offset = 0; offset < 32 * 64; offset += 64) __builtin_prefetch(rows + offset);
    }
    stack[size++] = {node, distance};
  };
  push(0, node_box_distance(0));
  while (size > 0) {
    const Pending top = stack[--size];
    if (!(top.distance < best.distance)) continue;
    const Node& node = tree.nodes[top.node];
    if (node.first_child < 0) {
      tree.scan(tree.blocks, node.first_block, node.last_block, tree.dims, query, filter, best);
      continue;
    }
    const int a = node.first_child;
    const int b = node.first_child + 1;
    const float da = node_box_distance(a);
    const float db = node_box_distance(b);
    // Push the farther child first so the nearer one is searched first.
    if (da <= db) {
      if (db < best.distance) push(b, db);
      if (da < best.distance) push(a, da);
    } else {
      if (da < best.distance) push(a, da);
      if (db < best.distance) push(b, db);
    }
  }
}

__attribute__((target("avx2,fma"))) void traverse_avx2(const TreeView& tree, const float* query,
                                                       const search_kernels::RowFilter& filter,
                                                       bool tag_filter,
                                                       search_kernels::ScanBest& best) {
  traverse(tree, query, filter, tag_filter, best);
}

void traverse_portable(const TreeView& tree, const float* query,
                       const search_kernels::RowFilter& filter, bool tag_filter,
                       search_kernels::ScanBest& best) {
  traverse(tree, query, filter, tag_filter, best);
}

using TraverseFn = void (*)(const TreeView&, const float*, const search_kernels::RowFilter&, bool,
                            search_kernels::ScanBest&);

// The best row over all groups so far: its canonical distance (or the plan's bound) and its
// candidate row.
struct SharedBest {
  float distance = 0.0f;
  int row = -1;
};

// One tree over a group of candidate rows, in the group's own principal axes (or the raw
// columns).
class BoxTree {
 public:
  // Builds the tree over candidate rows `rows` of `set`.
  void build(const CandidateSet& set, const std::vector<int>& rows, bool rotate, int leaf_rows) {
    const int count = static_cast<int>(rows.size());
    const int dims = set.dims;
    const auto row_size = static_cast<size_t>(dims);
    padded_dims_ = (dims + 7) / 8 * 8;
    // In principal axes the leading columns carry nearly all the spread: node boxes keep only
    // those (one or two vectors), and the root box bounds the rest once per query.
    box_dims_ = rotate ? std::min(padded_dims_, kRotatedBoxDims) : padded_dims_;
    leaf_rows_ = leaf_rows;
    // The rows in the space the tree lives in, kept in tree order while the tree is split:
    // every split partitions its range into the other buffer in one streaming pass.
    std::vector<float> work(static_cast<size_t>(count) * row_size);
    for (int i = 0; i < count; ++i) {
      std::copy_n(set.row(rows[static_cast<size_t>(i)]), dims,
                  work.data() + static_cast<size_t>(i) * row_size);
    }
    if (rotate && count > 0) {
      rotation_ = principal_axes(work.data(), count, dims, 4096);
      max_row_norm_ = rotate_rows(rotation_, work.data(), count, dims, row_size);
    }
    // The packed blocks are written last; until then their storage is the second row buffer.
    blocks_.resize(std::max(search_kernels::blocked_float_count(count, dims), work.size()));
    SplitBuffers buffers;
    buffers.rows[0] = work.data();
    buffers.rows[1] = blocks_.data();
    buffers.ids[0] = rows;
    buffers.ids[1].resize(rows.size());
    if (count > 0) {
      nodes_.emplace_back();
      buffers.keys.resize(static_cast<size_t>(count));
      split(0, 0, count, dims, buffers, 0, 1);
    }
    tree_row_ = std::move(buffers.ids[0]);
    blocks_.resize(search_kernels::blocked_float_count(count, dims));
    search_kernels::pack_blocks(work.data(), count, dims, blocks_.data());
    blocks_.shrink_to_fit();
    tree_frame_.resize(static_cast<size_t>(count));
    tree_tags_.resize(static_cast<size_t>(count));
    for (int i = 0; i < count; ++i) {
      const auto r = static_cast<size_t>(tree_row_[static_cast<size_t>(i)]);
      tree_frame_[static_cast<size_t>(i)] = set.row_frame[r];
      tree_tags_[static_cast<size_t>(i)] = set.row_tags[r];
    }
    const int block_count = (count + kBlockRows - 1) / kBlockRows;
    block_tags_or_.assign(static_cast<size_t>(block_count), 0);
    block_tags_and_.assign(static_cast<size_t>(block_count), ~uint64_t{0});
    for (int i = 0; i < count; ++i) {
      block_tags_or_[static_cast<size_t>(i / kBlockRows)] |= tree_tags_[static_cast<size_t>(i)];
      block_tags_and_[static_cast<size_t>(i / kBlockRows)] &= tree_tags_[static_cast<size_t>(i)];
    }
    compute_boxes(work, count, dims);
  }

  // Searches the group for rows that beat `shared`, with the plan's rules.
  void search(const CandidateSet& set, const float* query, const QueryPlan& plan, bool tag_filter,
              TraverseFn traverse_fn, search_kernels::ScanBlocksFn scan, SharedBest& shared) const {
    if (nodes_.empty()) return;
    search_kernels::RowFilter filter = plan.filter;
    filter.row_tags = tree_tags_.data();
    filter.row_frame = tree_frame_.data();
    filter.row_count = static_cast<int>(tree_row_.size());
    if (tag_filter) {
      filter.block_tags_or = block_tags_or_.data();
      filter.block_tags_and = block_tags_and_.data();
    }
    alignas(32) float point[kMaxSearchDims + 8] = {};
    search_kernels::ScanBest best;
    ExactRanker ranker;
    if (!rotation_.empty()) {
      rotation_.apply(query, point);
      ranker.start(set, rotation_, query, shared.distance, row_norm(point, set.dims),
                   max_row_norm_);
      ranker.scanned_to_set = tree_row_.data();
      filter.offer = &ExactRanker::offer;
      filter.offer_context = &ranker;
      best.distance = ranker.threshold();
    } else {
      std::copy_n(query, set.dims, point);
      best.distance = shared.distance;
    }
    // Every row is inside the root box: over the columns the node boxes leave out, its distance
    // to the query is at least the root box's.
    float base = 0.0f;
    if (box_dims_ < padded_dims_) {
      base = box_distance(point + box_dims_, root_box_.data() + box_dims_,
                          root_box_.data() + padded_dims_ + box_dims_, padded_dims_ - box_dims_);
    }
    const TreeView view{nodes_.data(),
                        boxes_.data(),
                        node_tags_or_.data(),
                        node_tags_and_.data(),
                        blocks_.data(),
                        set.dims,
                        box_dims_,
                        base,
                        scan};
    traverse_fn(view, point, filter, tag_filter, best);
    int found = best.row;
    float found_distance = best.distance;
    if (!rotation_.empty()) {
      ranker.resolve();
      found = ranker.best_row;
      found_distance = ranker.best_distance;
    }
    if (found >= 0) {
      shared.distance = found_distance;
      shared.row = tree_row_[static_cast<size_t>(found)];
    }
  }

  size_t memory_bytes() const {
    return rotation_.memory_bytes() + tree_row_.capacity() * sizeof(int) +
           tree_frame_.capacity() * sizeof(int) + tree_tags_.capacity() * sizeof(uint64_t) +
           blocks_.capacity() * sizeof(float) +
           (block_tags_or_.capacity() + block_tags_and_.capacity()) * sizeof(uint64_t) +
           nodes_.capacity() * sizeof(Node) +
           (boxes_.capacity() + root_box_.capacity()) * sizeof(float) +
           (node_tags_or_.capacity() + node_tags_and_.capacity()) * sizeof(uint64_t);
  }

 private:
  // Buffers of the split: one key per row, the two row buffers a split alternates between,
  // and the candidate rows that travel with the rows.
  struct SplitBuffers {
    std::vector<float> keys;
    float* rows[2] = {nullptr, nullptr};  // rows[0] is where the tree-ordered rows end up
    std::vector<int> ids[2];
  };

  // Splits node `id` over tree rows [first, last) (first is a multiple of 8), unless it is small
  // enough for a leaf: at a block boundary near the median of the widest dimension, estimated
  // from at most ~32 evenly spaced rows (exact boxes come later, bottom-up). The range's rows
  // are in buffer `from`; a split partitions them into the other buffer (one streaming pass),
  // and a leaf copies them to buffer 0 if they are not there already.
  void split(int id, int first, int last, int dims, SplitBuffers& buffers, int from, int depth) {
    const auto row_size = static_cast<size_t>(dims);
    const float* source = buffers.rows[from];
    nodes_[static_cast<size_t>(id)].first_block = first / kBlockRows;
    nodes_[static_cast<size_t>(id)].last_block = (last + kBlockRows - 1) / kBlockRows;
    const int count = last - first;
    auto make_leaf = [&] {
      if (from != 0) {
        std::copy_n(source + static_cast<size_t>(first) * row_size,
                    static_cast<size_t>(count) * row_size,
                    buffers.rows[0] + static_cast<size_t>(first) * row_size);
        std::copy_n(buffers.ids[from].data() + first, count, buffers.ids[0].data() + first);
      }
    };
    if (count <= leaf_rows_ || depth >= kMaxTreeDepth) return make_leaf();
    float lo[kMaxSearchDims];
    float hi[kMaxSearchDims];
    auto widest_dimension = [&](int step) {
      std::fill(lo, lo + dims, std::numeric_limits<float>::infinity());
      std::fill(hi, hi + dims, -std::numeric_limits<float>::infinity());
      for (int i = first; i < last; i += step) {
        const float* row = source + static_cast<size_t>(i) * row_size;
        for (int d = 0; d < dims; ++d) {
          lo[d] = std::min(lo[d], row[d]);
          hi[d] = std::max(hi[d], row[d]);
        }
      }
      int widest = 0;
      for (int d = 1; d < dims; ++d) {
        if (hi[d] - lo[d] > hi[widest] - lo[widest]) widest = d;
      }
      return widest;
    };
    int split_dim = widest_dimension(std::max(1, count / 32));
    if (!(hi[split_dim] > lo[split_dim])) split_dim = widest_dimension(1);
    if (!(hi[split_dim] > lo[split_dim])) return make_leaf();  // all rows equal
    // The split position is a block boundary, so that every leaf but the last is whole blocks.
    const int half_blocks = std::max(1, (count / kBlockRows) / 2);
    const int left_size = half_blocks * kBlockRows;
    if (left_size >= count) return make_leaf();
    // The pivot is the key of rank left_size: rows below it go left, rows above it right, and
    // rows equal to it fill the left side up to its size.
    float* keys = buffers.keys.data() + first;
    for (int i = 0; i < count; ++i)
      keys[i] = source[static_cast<size_t>(first + i) * row_size + split_dim];
    std::nth_element(keys, keys + left_size, keys + count);
    const float pivot = keys[left_size];
    int less = 0;
    for (int i = 0; i < left_size; ++i) less += keys[i] < pivot;
    int equal_to_left = left_size - less;
    const int to_buffer = 1 - from;
    float* target = buffers.rows[to_buffer] + static_cast<size_t>(first) * row_size;
    int* target_ids = buffers.ids[to_buffer].data() + first;
    const int* source_ids = buffers.ids[from].data() + first;
    int left = 0;
    int right = left_size;
    for (int i = 0; i < count; ++i) {
      const float* row = source + static_cast<size_t>(first + i) * row_size;
      const float key = row[split_dim];
      const bool goes_left = key < pivot || (key == pivot && equal_to_left-- > 0);
      const int to = goes_left ? left++ : right++;
      float* out = target + static_cast<size_t>(to) * row_size;
      for (size_t d = 0; d < row_size; ++d) out[d] = row[d];
      target_ids[to] = source_ids[i];
    }
    const int child = static_cast<int>(nodes_.size());
    nodes_[static_cast<size_t>(id)].first_child = child;
    nodes_.emplace_back();
    nodes_.emplace_back();
    split(child, first, first + left_size, dims, buffers, to_buffer, depth + 1);
    split(child + 1, first + left_size, last, dims, buffers, to_buffer, depth + 1);
  }

  // Tight boxes and tag summaries, bottom-up: children always come after their parent, so a
  // reverse sweep sees both children before the parent. Leaves read their rows in tree order.
  // Node boxes cover the first box_dims_ columns; the root box covers all of them.
  void compute_boxes(const std::vector<float>& ordered, int rows, int dims) {
    const int box_dims = std::min(box_dims_, dims);
    const size_t box_stride = 2 * static_cast<size_t>(box_dims_);
    boxes_.assign(nodes_.size() * box_stride, 0.0f);
    node_tags_or_.assign(nodes_.size(), 0);
    node_tags_and_.assign(nodes_.size(), ~uint64_t{0});
    for (size_t n = nodes_.size(); n-- > 0;) {
      const Node& node = nodes_[n];
      float* lo = boxes_.data() + n * box_stride;
      float* hi = lo + box_dims_;
      if (node.first_child < 0) {
        std::fill(lo, lo + box_dims, std::numeric_limits<float>::infinity());
        std::fill(hi, hi + box_dims, -std::numeric_limits<float>::infinity());
        const int last = std::min(rows, node.last_block * kBlockRows);
        for (int i = node.first_block * kBlockRows; i < last; ++i) {
          const float* row = ordered.data() + static_cast<size_t>(i) * dims;
          for (int d = 0; d < box_dims; ++d) {
            lo[d] = std::min(lo[d], row[d]);
            hi[d] = std::max(hi[d], row[d]);
          }
        }
        for (int b = node.first_block; b < node.last_block; ++b) {
          node_tags_or_[n] |= block_tags_or_[static_cast<size_t>(b)];
          node_tags_and_[n] &= block_tags_and_[static_cast<size_t>(b)];
        }
      } else {
        const auto a = static_cast<size_t>(node.first_child);
        const float* box_a = boxes_.data() + a * box_stride;
        const float* box_b = box_a + box_stride;
        for (int d = 0; d < box_dims; ++d) {
          lo[d] = std::min(box_a[d], box_b[d]);
          hi[d] = std::max(box_a[box_dims_ + d], box_b[box_dims_ + d]);
        }
        node_tags_or_[n] = node_tags_or_[a] | node_tags_or_[a + 1];
        node_tags_and_[n] = node_tags_and_[a] & node_tags_and_[a + 1];
      }
    }
    root_box_.assign(2 * static_cast<size_t>(padded_dims_), 0.0f);
    if (rows == 0) return;
    float* lo = root_box_.data();
    float* hi = lo + padded_dims_;
    std::fill(lo, lo + dims, std::numeric_limits<float>::infinity());
    std::fill(hi, hi + dims, -std::numeric_limits<float>::infinity());
    for (int i = 0; i < rows; ++i) {
      const float* row = ordered.data() + static_cast<size_t>(i) * dims;
      for (int d = 0; d < dims; ++d) {
        lo[d] = std::min(lo[d], row[d]);
        hi[d] = std::max(hi[d], row[d]);
      }
    }
  }

  FeatureRotation rotation_;  // empty when the tree is over the raw columns
  float max_row_norm_ = 0.0f;
  int padded_dims_ = 8;
  int box_dims_ = 8;  // columns covered by the node boxes
  int leaf_rows_ = 32;
  std::vector<int> tree_row_;        // tree order -> candidate row
  std::vector<int> tree_frame_;      // tree order -> frame
  std::vector<uint64_t> tree_tags_;  // tree order -> clip tags
  std::vector<float> blocks_;        // tree-ordered rows (in the tree's space), packed
  std::vector<uint64_t> block_tags_or_;
  std::vector<uint64_t> block_tags_and_;
  std::vector<Node> nodes_;      // node 0 is the root
  std::vector<float> boxes_;     // per node: lows then highs, box_dims_ each
  std::vector<float> root_box_;  // lows then highs over all columns, padded_dims_ each
  std::vector<uint64_t> node_tags_or_;
  std::vector<uint64_t> node_tags_and_;
};

class BoxTreeSearcher final : public Searcher {
 public:
  BoxTreeSearcher(const SearchInput& input, const SearchOptions& options)
      : set_(make_candidate_set(input)) {
    std::vector<std::vector<int>> rows;
    groups_ = make_row_groups(set_, options.boxtree_group_rows, rows);
    trees_.resize(rows.size());
    for (size_t g = 0; g < rows.size(); ++g) {
      trees_[g].build(set_, rows[g], options.principal_axes, options.boxtree_leaf_size);
    }
    traverse_ = search_kernels::avx2_supported() ? &traverse_avx2 : &traverse_portable;
    // In principal axes most rows of a visited leaf are decided by their first 8 or 16 columns.
    scan_ = options.principal_axes ? search_kernels::scan_blocks_staged()
                                   : search_kernels::scan_blocks();
  }

  std::string_view method() const override { return "boxtree"; }
  int dims() const override { return set_.dims; }
  bool exact() const override { return true; }
  size_t memory_bytes() const override {
    size_t bytes = set_.memory_bytes() + groups_.memory_bytes();
    for (const BoxTree& tree : trees_) bytes += tree.memory_bytes();
    return bytes;
  }

  SearchResult search(std::span<const float> query,
                      const SearchConstraints& constraints) const override {
    MM_ASSERT(static_cast<int>(query.size()) == set_.dims);
    const QueryPlan plan = plan_query(set_, query.data(), constraints);
    if (!(plan.bound > 0.0f) || trees_.empty()) {
      return finish_query(set_, plan, query.data(), -1, constraints);
    }
    const bool tag_filter = constraints.include_tags != 0 || constraints.exclude_tags != 0;
    GroupDistance order[kMaxGroups];
    const int count = groups_.order(query.data(), constraints, order);
    SharedBest best;
    best.distance = plan.bound;
    for (int i = 0; i < count && !RowGroups::beyond(order[i].distance, best.distance); ++i) {
      trees_[static_cast<size_t>(order[i].group)].search(set_, query.data(), plan, tag_filter,
                                                         traverse_, scan_, best);
    }
    return finish_query(set_, plan, query.data(), best.row, constraints);
  }

 private:
  CandidateSet set_;
  RowGroups groups_;
  std::vector<BoxTree> trees_;  // one per group
  TraverseFn traverse_ = nullptr;
  search_kernels::ScanBlocksFn scan_ = nullptr;
};

}  // namespace

Result<std::unique_ptr<Searcher>> make_boxtree(const SearchInput& input,
                                               const SearchOptions& options) {
  if (options.boxtree_leaf_size < kBlockRows || options.boxtree_leaf_size % kBlockRows != 0) {
    return Error{"boxtree: leaf size must be a positive multiple of 8 rows, got " +
                 std::to_string(options.boxtree_leaf_size)};
  }
  if (options.boxtree_group_rows < 0) {
    return Error{"boxtree: rows per group must be >= 0 (0: one group), got " +
                 std::to_string(options.boxtree_group_rows)};
  }
  return std::unique_ptr<Searcher>(std::make_unique<BoxTreeSearcher>(input, options));
}

}  // namespace mm::search_detail
