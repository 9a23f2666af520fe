#include "mm/controller/style_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "mm/controller/controller.hpp"

namespace mm {

namespace {

// The cheaper answer; on a tie the continuation (it needs no transition), then `a`.
SearchResult better(const SearchResult& a, const SearchResult& b) {
  if (b.frame < 0) return a;
  if (a.frame < 0) return b;
  if (b.cost < a.cost || (b.cost == a.cost && b.continuation && !a.continuation)) return b;
  return a;
}

SearchResult with_cost(SearchResult r, float added) {
  if (r.frame >= 0) r.cost += added;
  return r;
}

// A style is rich when it has at least this share of the largest style's frames: the Bandai
// thin styles hold about a twentieth of a rich one, and lack whole moves (turns).
constexpr double kRichShare = 0.25;

}  // namespace

StyleTiers style_tiers(const ControllerDatabase& database, int style, float style_cost,
                       float style_fallback_step) {
  StyleTiers t;
  t.own = database.style_tags(style);
  if (t.own == 0) return t;
  t.all = database.all_style_tags();
  t.styleless_tags = database.styleless_clip_tags();
  for (int rank = 0; rank < 2; ++rank) {
    t.fallback[rank] = database.style_tags(database.style_fallback(style, rank));
    t.fallback_cost[rank] = style_cost + static_cast<float>(rank) * style_fallback_step;
  }
  t.other_cost = style_cost + 2.0f * style_fallback_step;
  return t;
}

SearchResult search_in_style(const Searcher& searcher, std::span<const float> query,
                             const SearchConstraints& constraints, const StyleTiers& tiers) {
  if (tiers.own == 0) return searcher.search(query, constraints);
  // The requested style's own frames, then the clips without a style (they serve every style).
  SearchConstraints own = constraints;
  own.include_tags |= tiers.own;
  SearchResult best = searcher.search(query, own);
  bool any_styleless = false;
  for (const uint64_t tags : tiers.styleless_tags) {
    any_styleless |= (tags & constraints.include_tags) == constraints.include_tags &&
                     (tags & constraints.exclude_tags) == 0;
  }
  if (any_styleless) {
    SearchConstraints styleless = constraints;
    styleless.exclude_tags |= tiers.all;
    best = better(best, searcher.search(query, styleless));
  }
  uint64_t searched = tiers.own;
  // Tiers in order of their added cost: a frame of a later tier costs at least its added cost
  // (plain costs are >= 0), so once the best so far is within it nothing later can win.
  for (int rank = 0; rank < 2; ++rank) {
    if (tiers.fallback[rank] == 0) continue;
    if (best.frame >= 0 && best.cost <= tiers.fallback_cost[rank]) return best;
    SearchConstraints c = constraints;
    c.include_tags |= tiers.fallback[rank];
    best = better(best, with_cost(searcher.search(query, c), tiers.fallback_cost[rank]));
    searched |= tiers.fallback[rank];
  }
  if (best.frame >= 0 && best.cost <= tiers.other_cost) return best;
  SearchConstraints others = constraints;
  others.exclude_tags |= searched;
  // Style-less frames are among `others` too; they already competed at their plain cost, and
  // the added cost only makes them lose to their own answer above.
  return better(best, with_cost(searcher.search(query, others), tiers.other_cost));
}

void ControllerDatabase::resolve_style_tags() {
  const Database& db = *database_;
  style_tags_.assign(db.style_names().size(), 0);
  all_style_tags_ = 0;
  for (size_t s = 0; s < db.style_names().size(); ++s) {
    style_tags_[s] = db.tag_mask(std::vector<std::string>{db.style_names()[s]});
    all_style_tags_ |= style_tags_[s];
  }
  styleless_clip_tags_.clear();
  for (const ClipRange& clip : db.clips()) {
    if (clip.style >= 0) continue;
    if (std::find(styleless_clip_tags_.begin(), styleless_clip_tags_.end(), clip.tags) ==
        styleless_clip_tags_.end()) {
      styleless_clip_tags_.push_back(clip.tags);
    }
  }
  resolve_style_fallbacks();
}

// Each style's fallback order: the nearest rich style (not itself), then "normal" when the
// database has it and it is neither. "Near" compares the styles' walking gait: the mean and the
// standard deviation of every pose feature column (feet positions and velocities, hips
// velocity: not the trajectory, which the stick sets) over the searchable frames of the style's
// clips tagged "walk" (all its searchable frames when it has none), in normalized feature
// units; the distance is the Euclidean one over those statistics.
void ControllerDatabase::resolve_style_fallbacks() {
  const Database& db = *database_;
  const size_t styles = db.style_names().size();
  style_fallbacks_.assign(styles, {-1, -1});
  style_rich_.assign(styles, 0);
  if (styles == 0) return;
  std::vector<int> pose_columns;
  for (size_t ch = 0; ch < db.schema().channels.size(); ++ch) {
    const FeatureChannel& c = db.schema().channels[ch];
    if (c.kind == FeatureKind::TrajectoryPosition || c.kind == FeatureKind::TrajectoryDirection) {
      continue;
    }
    const int first = db.schema().offset(static_cast<int>(ch));
    for (int k = 0; k < c.dims(); ++k) pose_columns.push_back(first + k);
  }
  const uint64_t walk = db.tag_mask(std::vector<std::string>{"walk"});
  const size_t dims = static_cast<size_t>(db.feature_dims());
  const size_t cols = pose_columns.size();
  std::vector<double> sum(styles * cols, 0.0), sum2(styles * cols, 0.0);
  std::vector<double> frames(styles, 0.0), walk_frames(styles, 0.0);
  for (int pass = 0; pass < 2; ++pass) {
    for (const ClipRange& clip : db.clips()) {
      if (clip.style < 0) continue;
      const size_t s = static_cast<size_t>(clip.style);
      // Pass 0 counts; pass 1 sums the walk frames, or every frame of a style without walks.
      const bool walking = walk != 0 && (clip.tags & walk) == walk;
      for (int f = clip.start; f < clip.end; ++f) {
        if (!db.searchable()[static_cast<size_t>(f)]) continue;
        if (pass == 0) {
          frames[s] += 1.0;
          if (walking) walk_frames[s] += 1.0;
          continue;
        }
        if (walk_frames[s] > 0.0 && !walking) continue;
        const float* row = db.features().data() + static_cast<size_t>(f) * dims;
        for (size_t k = 0; k < cols; ++k) {
          const double v = row[pose_columns[k]];
          sum[s * cols + k] += v;
          sum2[s * cols + k] += v * v;
        }
      }
    }
  }
  const double largest = *std::max_element(frames.begin(), frames.end());
  std::vector<double> stats(styles * cols * 2, 0.0);
  for (size_t s = 0; s < styles; ++s) {
    style_rich_[s] = largest > 0.0 && frames[s] >= kRichShare * largest ? 1 : 0;
    const double n = walk_frames[s] > 0.0 ? walk_frames[s] : frames[s];
    if (n <= 0.0) continue;
    for (size_t k = 0; k < cols; ++k) {
      const double mean = sum[s * cols + k] / n;
      stats[(s * cols + k) * 2] = mean;
      stats[(s * cols + k) * 2 + 1] =
          std::sqrt(std::max(0.0, sum2[s * cols + k] / n - mean * mean));
    }
  }
  int normal = -1;
  for (size_t s = 0; s < styles; ++s) {
    if (db.style_names()[s] == "normal") normal = static_cast<int>(s);
  }
  for (size_t s = 0; s < styles; ++s) {
    int nearest = -1;
    double nearest_distance = std::numeric_limits<double>::infinity();
    for (size_t r = 0; r < styles; ++r) {
      if (r == s || !style_rich_[r]) continue;
      double d = 0.0;
      for (size_t k = 0; k < cols * 2; ++k) {
        const double diff = stats[s * cols * 2 + k] - stats[r * cols * 2 + k];
        d += diff * diff;
      }
      if (d < nearest_distance) {
        nearest_distance = d;
        nearest = static_cast<int>(r);
      }
    }
    auto& order = style_fallbacks_[s];
    order[0] = nearest;
    const bool normal_new = normal >= 0 && normal != static_cast<int>(s) && normal != nearest;
    if (normal_new) (nearest < 0 ? order[0] : order[1]) = normal;
  }
}

Result<int> ControllerDatabase::style_id(std::string_view name) const {
  const auto names = database_->style_names();
  for (size_t s = 0; s < names.size(); ++s) {
    if (names[s] == name) return static_cast<int>(s);
  }
  if (names.empty()) {
    return Error{"unknown style '" + std::string(name) +
                 "': the database has no styles (rebuild it with styled clips: Bandai names or "
                 "a manifest's style=NAME)"};
  }
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  return Error{"unknown style '" + std::string(name) + "'; the database's styles are " + list};
}

}  // namespace mm
