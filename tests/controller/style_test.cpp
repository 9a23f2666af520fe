// Styles on a database of several: the fallback order derived from the styles' gait statistics,
// the search with the style tiers against a brute-force scan over every frame, what plays when
// a thin style lacks the move, determinism and the request through scripts.
//
// The styled database is the normal database copied per style: "near", "far" and "normal" hold
// every locomotion clip, "thin" only the straight walks (no turns, no strafes), the idle stays
// style-less. Copies of identical features make the fallback observable: without an order, a
// frame of any copy could win a tie.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "controller_support.hpp"
#include "mm/controller/controller.hpp"
#include "mm/controller/script.hpp"
#include "mm/controller/style_search.hpp"

namespace mm {
namespace {

bool has_any_tag(const DatabaseContents& db, const ClipRange& clip, std::string_view prefix,
                 bool exact) {
  for (size_t t = 0; t < db.tag_names.size(); ++t) {
    if (!(clip.tags & (uint64_t{1} << t))) continue;
    const std::string& name = db.tag_names[t];
    if (exact ? name == prefix : name.rfind(prefix, 0) == 0) return true;
  }
  return false;
}

// The normal database copied per style, in frame order far, near, normal, thin (style-less
// clips once, with normal); `names` orders the style ids. `far_offset` is added to every pose
// feature column (not the trajectory) of the far copy.
std::shared_ptr<const ControllerDatabase> styled_database(const std::vector<std::string>& names,
                                                          float far_offset) {
  const DatabaseContents base = test::normal_controller_database()->database().contents();
  DatabaseContents out = base;
  const size_t joints = static_cast<size_t>(base.joint_count());
  const size_t dims = static_cast<size_t>(base.feature_dims());
  out.local_positions.clear();
  out.local_rotations.clear();
  out.local_velocities.clear();
  out.local_angular_velocities.clear();
  out.contacts.clear();
  out.features.clear();
  out.searchable.clear();
  out.clips.clear();
  out.style_names = names;
  uint64_t old_style_tags = 0;
  for (const std::string& s : base.style_names) {
    const auto it = std::find(base.tag_names.begin(), base.tag_names.end(), s);
    if (it != base.tag_names.end()) {
      old_style_tags |= uint64_t{1} << (it - base.tag_names.begin());
    }
  }
  for (const std::string& s : names) {
    if (std::find(out.tag_names.begin(), out.tag_names.end(), s) == out.tag_names.end()) {
      out.tag_names.push_back(s);
    }
  }
  const auto tag_of = [&](const std::string& s) {
    const auto it = std::find(out.tag_names.begin(), out.tag_names.end(), s);
    return uint64_t{1} << (it - out.tag_names.begin());
  };
  const auto id_of = [&](const std::string& s) {
    return static_cast<int>(std::find(names.begin(), names.end(), s) - names.begin());
  };
  std::vector<bool> pose_column(dims, true);
  for (size_t ch = 0; ch < base.schema.channels.size(); ++ch) {
    const FeatureKind kind = base.schema.channels[ch].kind;
    if (kind != FeatureKind::TrajectoryPosition && kind != FeatureKind::TrajectoryDirection) {
      continue;
    }
    const int first = base.schema.offset(static_cast<int>(ch));
    for (int k = 0; k < base.schema.channels[ch].dims(); ++k) {
      pose_column[static_cast<size_t>(first + k)] = false;
    }
  }
  int frames = 0;
  for (const std::string copy : {"far", "near", "normal", "thin"}) {
    for (const ClipRange& clip : base.clips) {
      const bool styleless = clip.style < 0;
      if (styleless && copy != std::string("normal")) continue;
      const bool straight_walk = has_any_tag(base, clip, "walk", true) &&
                                 !has_any_tag(base, clip, "walk-", false) &&
                                 !has_any_tag(base, clip, "run", true);
      if (copy == std::string("thin") && !straight_walk) continue;
      ClipRange c = clip;
      c.name = clip.name + "_" + copy;
      c.start = frames;
      c.end = frames + clip.frame_count();
      if (!styleless) {
        c.tags = (clip.tags & ~old_style_tags) | tag_of(copy);
        c.style = id_of(copy);
      }
      out.clips.push_back(c);
      const size_t a = static_cast<size_t>(clip.start), b = static_cast<size_t>(clip.end);
      out.local_positions.insert(out.local_positions.end(),
                                 base.local_positions.begin() + a * joints,
                                 base.local_positions.begin() + b * joints);
      out.local_rotations.insert(out.local_rotations.end(),
                                 base.local_rotations.begin() + a * joints,
                                 base.local_rotations.begin() + b * joints);
      out.local_velocities.insert(out.local_velocities.end(),
                                  base.local_velocities.begin() + a * joints,
                                  base.local_velocities.begin() + b * joints);
      out.local_angular_velocities.insert(out.local_angular_velocities.end(),
                                          base.local_angular_velocities.begin() + a * joints,
                                          base.local_angular_velocities.begin() + b * joints);
      out.contacts.insert(out.contacts.end(), base.contacts.begin() + a * 2,
                          base.contacts.begin() + b * 2);
      out.searchable.insert(out.searchable.end(), base.searchable.begin() + a,
                            base.searchable.begin() + b);
      for (size_t f = a; f < b; ++f) {
        for (size_t k = 0; k < dims; ++k) {
          const float v = base.features[f * dims + k];
          out.features.push_back(copy == std::string("far") && pose_column[k] ? v + far_offset : v);
        }
      }
      frames += clip.frame_count();
    }
  }
  out.frame_count = frames;
  Result<Database> db = Database::create(out);
  EXPECT_TRUE(db) << (db ? "" : db.message());
  if (!db) return nullptr;
  Result<std::shared_ptr<const ControllerDatabase>> shared =
      ControllerDatabase::create(std::make_shared<const Database>(std::move(db).value()));
  EXPECT_TRUE(shared) << (shared ? "" : shared.message());
  return shared ? *shared : nullptr;
}

// Ties in the statistics go to the lower style id: near (0) before normal.
const std::vector<std::string> kNearFirst = {"near", "far", "normal", "thin"};

int id(const ControllerDatabase& db, std::string_view name) {
  const Result<int> r = db.style_id(name);
  EXPECT_TRUE(r) << (r ? "" : r.message());
  return r ? *r : -1;
}

TEST(ControllerStyleFallback, TheNearestRichStyleByGaitStatisticsThenNormal) {
  // far comes first by id but its gait statistics are off by the offset: near is nearer.
  const auto db = styled_database({"far", "near", "normal", "thin"}, 0.5f);
  ASSERT_TRUE(db);
  const int far = id(*db, "far"), near = id(*db, "near"), normal = id(*db, "normal");
  const int thin = id(*db, "thin");
  EXPECT_FALSE(db->style_rich(thin));
  EXPECT_TRUE(db->style_rich(far));
  EXPECT_TRUE(db->style_rich(near));
  EXPECT_TRUE(db->style_rich(normal));
  EXPECT_EQ(db->style_fallback(thin, 0), near);
  EXPECT_EQ(db->style_fallback(thin, 1), normal);
  // near and normal hold the same frames: each is the other's nearest, with nothing after.
  EXPECT_EQ(db->style_fallback(normal, 0), near);
  EXPECT_EQ(db->style_fallback(normal, 1), -1);
  EXPECT_EQ(db->style_fallback(near, 0), normal);
  EXPECT_EQ(db->style_fallback(near, 1), -1);
  EXPECT_EQ(db->style_fallback(far, 0), near);
  EXPECT_EQ(db->style_fallback(far, 1), normal);
  EXPECT_EQ(db->style_fallback(-1, 0), -1);
  EXPECT_EQ(db->style_fallback(thin, 2), -1);
}

// The cost of `frame` for `query` by the search rules, plus the tier its clip's style pays.
double brute_cost(const ControllerDatabase& db, std::span<const float> query,
                  const SearchConstraints& c, const StyleTiers& tiers, int frame) {
  const Database& d = db.database();
  const ClipRange& clip =
      d.clips()[static_cast<size_t>(d.frame_clip()[static_cast<size_t>(frame)])];
  if (!db.candidates()[static_cast<size_t>(frame)]) return std::numeric_limits<double>::infinity();
  if ((clip.tags & c.include_tags) != c.include_tags || (clip.tags & c.exclude_tags) != 0) {
    return std::numeric_limits<double>::infinity();
  }
  const bool next = c.current_frame >= 0 && frame == c.current_frame + 1 &&
                    d.frame_clip()[static_cast<size_t>(frame)] ==
                        d.frame_clip()[static_cast<size_t>(c.current_frame)];
  if (!next && c.current_frame >= 0 && std::abs(frame - c.current_frame) <= c.window_frames) {
    return std::numeric_limits<double>::infinity();
  }
  const size_t dims = static_cast<size_t>(d.feature_dims());
  double cost = next ? 0.0 : c.transition_cost;
  for (size_t k = 0; k < dims; ++k) {
    const double diff = double(query[k]) - d.features()[static_cast<size_t>(frame) * dims + k];
    cost += diff * diff;
  }
  if (tiers.own == 0 || (clip.tags & tiers.all) == 0 || (clip.tags & tiers.own) != 0) {
    return cost;
  }
  for (int rank = 0; rank < 2; ++rank) {
    if (tiers.fallback[rank] != 0 && (clip.tags & tiers.fallback[rank]) != 0) {
      return cost + tiers.fallback_cost[rank];
    }
  }
  return cost + tiers.other_cost;
}

TEST(ControllerStyleFallback, TheTieredSearchEqualsABruteForceScanWithTheAddedCosts) {
  const auto db = styled_database(kNearFirst, 0.0f);
  ASSERT_TRUE(db);
  const Database& d = db->database();
  const size_t dims = static_cast<size_t>(d.feature_dims());
  std::mt19937 rng(31);
  std::normal_distribution<float> noise(0.0f, 0.7f);
  std::uniform_int_distribution<int> any_frame(0, d.frame_count() - 1);
  std::vector<float> query(dims);
  for (const std::string_view method : search_method_names()) {
    Result<const Searcher*> searcher = db->searcher(method);
    ASSERT_TRUE(searcher) << searcher.message();
    if (!(*searcher)->exact()) continue;  // kdtree-eps is only within a factor of the best
    for (int q = 0; q < 12; ++q) {
      const int row = any_frame(rng);
      for (size_t k = 0; k < dims; ++k) {
        query[k] = d.features()[static_cast<size_t>(row) * dims + k] + noise(rng);
      }
      SearchConstraints c;
      c.current_frame = any_frame(rng);
      c.window_frames = 6;
      c.transition_cost = 0.5f;
      // Half the queries let the style-less idle compete, half exclude it, as the controller
      // does while moving (then the style-less search is skipped: nothing could pass).
      c.exclude_tags = q % 2 == 0 ? db->action_tags() | db->idle_tags() : 0;
      for (int style = -1; style < db->style_count(); ++style) {
        for (const float step : {4.0f, 0.0f}) {
          const StyleTiers tiers = style_tiers(*db, style, 2.0f, step);
          const SearchResult got = search_in_style(**searcher, query, c, tiers);
          double best = std::numeric_limits<double>::infinity();
          for (int f = 0; f < d.frame_count(); ++f) {
            best = std::min(best, brute_cost(*db, query, c, tiers, f));
          }
          ASSERT_GE(got.frame, 0) << method;
          EXPECT_NEAR(got.cost, best, 1e-4 * std::max(1.0, best))
              << method << " style " << style << " step " << step << " query " << q;
          EXPECT_NEAR(brute_cost(*db, query, c, tiers, got.frame), best, 1e-4 * std::max(1.0, best))
              << method << " style " << style << " step " << step << " query " << q;
        }
      }
    }
  }
}

// The styles that played each update while the stick is pushed, turning round after 2 s.
std::vector<int> styles_while_turning(const std::shared_ptr<const ControllerDatabase>& db,
                                      int style, const ControllerSettings& settings) {
  Result<Controller> made = Controller::create(db, settings);
  EXPECT_TRUE(made) << (made ? "" : made.message());
  std::vector<int> played;
  if (!made) return played;
  for (int i = 0; i < 6 * 60; ++i) {
    ControllerInput input = test::push_toward(i < 2 * 60 ? 0.0f : (i < 4 * 60 ? 180.0f : 90.0f));
    input.style = style;
    made->update(1.0f / 60.0f, input);
    const int clip = made->debug().clip;
    if (clip >= 0) played.push_back(db->database().clips()[static_cast<size_t>(clip)].style);
  }
  return played;
}

TEST(ControllerStyleFallback, AThinStyleTurningPlaysItsNearestRichStyleNotAnyOther) {
  // far's pose features moved a little: for some queries its frames are the closest, but
  // never by the fallback step, so near's turn plays (with style_fallback_step 0, far's does).
  const auto db = styled_database(kNearFirst, 0.05f);
  ASSERT_TRUE(db);
  const int thin = id(*db, "thin"), near = id(*db, "near");
  ASSERT_EQ(db->style_fallback(thin, 0), near);
  const std::vector<int> played = styles_while_turning(db, thin, {});
  const auto count = [&](int s) { return std::count(played.begin(), played.end(), s); };
  EXPECT_GT(count(thin), 60);  // walking straight: its own walks
  EXPECT_GT(count(near), 0);   // turning round: the thin style has no turn, near has
  EXPECT_EQ(count(id(*db, "far")), 0);
  EXPECT_EQ(count(id(*db, "normal")), 0);
}

TEST(ControllerStyleFallback, TheSameScriptTwicePlaysTheSameFrames) {
  const auto db = styled_database(kNearFirst, 0.0f);
  ASSERT_TRUE(db);
  Result<InputScript> script = parse_input_script(
      "0 0 1 0 0 style=thin\n2 1 0 0 0 style=far\n3 1 0 0 0 run style=near\n"
      "4.5 0 -1 0 0 style=thin\n6 0 0 0 0\n7 0 0 0 0\n",
      "styles.txt");
  ASSERT_TRUE(script) << script.message();
  ASSERT_TRUE(script->resolve_styles(*db, "styles.txt", -1).ok());
  std::vector<std::vector<Transform>> runs[2];
  std::vector<int> requested;
  for (auto& run : runs) {
    Result<Controller> c = Controller::create(db);
    ASSERT_TRUE(c) << c.message();
    requested.clear();
    for (int i = 0; i < 7 * 60; ++i) {
      const ControllerInput input = script->at(static_cast<float>(i) / 60.0f);
      c->update(1.0f / 60.0f, input);
      requested.push_back(c->debug().requested_style);
      run.emplace_back(c->global_transforms().begin(), c->global_transforms().end());
    }
  }
  // The script's styles reach the controller as their ids.
  EXPECT_EQ(requested[60], id(*db, "thin"));
  EXPECT_EQ(requested[150], id(*db, "far"));
  EXPECT_EQ(requested[200], id(*db, "near"));
  ASSERT_EQ(runs[0].size(), runs[1].size());
  for (size_t f = 0; f < runs[0].size(); ++f) {
    for (size_t j = 0; j < runs[0][f].size(); ++j) {
      ASSERT_EQ(runs[0][f][j].translation, runs[1][f][j].translation) << f << " " << j;
      ASSERT_EQ(runs[0][f][j].rotation, runs[1][f][j].rotation) << f << " " << j;
    }
  }
}

TEST(ControllerStyleFallback, AnUnknownStyleOfAStyledDatabaseListsItsStyles) {
  const auto db = styled_database(kNearFirst, 0.0f);
  ASSERT_TRUE(db);
  const Result<int> r = db->style_id("proud");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.message(),
            "unknown style 'proud'; the database's styles are near, far, normal, thin");
}

}  // namespace
}  // namespace mm
