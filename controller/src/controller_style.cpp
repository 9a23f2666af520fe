#include "controller_style.hpp"

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

}  // namespace

SearchResult search_in_style(const Searcher& searcher, std::span<const float> query,
                             const SearchConstraints& constraints, uint64_t style_tags,
                             uint64_t all_style_tags, float style_cost) {
  if (style_tags == 0) return searcher.search(query, constraints);
  // The requested style's own frames, then the clips without a style (they serve every style).
  SearchConstraints own = constraints;
  own.include_tags |= style_tags;
  SearchConstraints styleless = constraints;
  styleless.exclude_tags |= all_style_tags;
  SearchResult best = better(searcher.search(query, own), searcher.search(query, styleless));
  // Every frame of another style costs at least style_cost: it cannot beat this.
  if (best.frame >= 0 && best.cost <= style_cost) return best;
  SearchConstraints others = constraints;
  others.exclude_tags |= style_tags;
  others.include_tags &= ~all_style_tags;
  SearchResult other = searcher.search(query, others);
  // Style-less frames are among `others` too; they already competed at their plain cost, and
  // the added cost only makes them lose to their own answer above.
  if (other.frame >= 0) other.cost += style_cost;
  return better(best, other);
}

void ControllerDatabase::resolve_style_tags() {
  const Database& db = *database_;
  style_tags_.assign(db.style_names().size(), 0);
  all_style_tags_ = 0;
  for (size_t s = 0; s < db.style_names().size(); ++s) {
    style_tags_[s] = db.tag_mask(std::vector<std::string>{db.style_names()[s]});
    all_style_tags_ |= style_tags_[s];
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
