// The database builder on real Bandai clips (two walks, a turn, a run and a wave), on bad
// inputs, and end to end through the database file. The idle clip has its own tests
// (idle_test.cpp); here it is accounted for where the default build makes one.

#include <gtest/gtest.h>

#include <optional>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>

#include "database_helpers.hpp"
#include "mm/database/database_file.hpp"
#include "mm/offline/builder.hpp"
#include "mm/offline/bvh.hpp"
#include "mm/offline/database_writer.hpp"
#include "mm/offline/feature_extraction.hpp"
#include "mm/offline/gltf.hpp"
#include "mm/offline/idle.hpp"
#include "mm/runtime/pose.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

namespace fs = std::filesystem;

const char* const kClips[] = {"dataset-2_walk_normal_001", "dataset-2_walk_normal_002",
                              "dataset-2_walk-turn-left_normal_001", "dataset-2_run_normal_001",
                              "dataset-2_wave-both-hands_normal_001"};

std::vector<fs::path> clip_paths() {
  std::vector<fs::path> paths;
  for (const char* name : kClips) paths.push_back(test::clip_path(name));
  return paths;
}

// The five clips are built once and shared by the tests that only read the result.
struct Built {
  std::optional<Database> db;
  BuildReport report;
  std::vector<Clip> sources;  // the same files, loaded independently
};

const Built& built() {
  static const Built b = [] {
    Built out;
    const std::vector<fs::path> paths = clip_paths();
    Result<Database> db = build_database(paths, BuildOptions{}, &out.report);
    EXPECT_TRUE(db) << db.message();
    if (db) out.db.emplace(std::move(db).value());
    for (const fs::path& p : paths) {
      Result<Clip> clip = load_bvh(p);
      EXPECT_TRUE(clip) << clip.message();
      if (clip) out.sources.push_back(std::move(clip).value());
    }
    return out;
  }();
  return b;
}

using test::has_tag;

std::vector<Transform> source_globals(const Clip& clip, int frame) {
  std::vector<Transform> global(clip.joint_count());
  forward_kinematics(clip.skeleton.parents(), clip.pose(frame), global);
  return global;
}

// A small, valid BVH with a different skeleton (Hips, LeftFoot, RightFoot), in centimetres.
// Hips with two legs (upper leg, lower leg, foot) whose upper and lower legs sit at the hips:
// 7 joints, every one with 3 rotation channels and the hips with 3 position channels too.
std::string other_skeleton_bvh() {
  auto leg = [](const char* side, const char* x) {
    return std::string("  JOINT ") + side + "UpLeg\n  {\n    OFFSET " + x +
           " 0 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n    JOINT " + side +
           "Leg\n    {\n      OFFSET 0 -40 0\n      CHANNELS 3 Zrotation Xrotation "
           "Yrotation\n      JOINT " +
           side +
           "Foot\n      {\n        OFFSET 0 -40 0\n        CHANNELS 3 Zrotation Xrotation "
           "Yrotation\n        End Site\n        {\n          OFFSET 0 0 10\n        }\n"
           "      }\n    }\n  }\n";
  };
  std::string text =
      "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 90 0\n  CHANNELS 6 Xposition Yposition Zposition "
      "Zrotation Xrotation Yrotation\n" +
      leg("Left", "10") + leg("Right", "-10") + "}\nMOTION\nFrames: 40\nFrame Time: 0.0333333\n";
  for (int f = 0; f < 40; ++f) {
    text += "0 90 " + std::to_string(f * 4) + " 0 0 0";
    for (int c = 0; c < 18; ++c) text += " 0";  // the six leg joints' rotations
    text += "\n";
  }
  return text;
}

// ---- The real clips ----------------------------------------------------------------------------

TEST(BuilderRealClips, FramesRangesAndSearchableCounts) {
  const Built& b = built();
  const DatabaseView db = *b.db;
  ASSERT_EQ(b.sources.size(), 5u);
  ASSERT_TRUE(validate_database(db)) << validate_database(db).message();
  // The five clips, then the idle clip (3 s by default).
  ASSERT_EQ(db.clips.size(), 6u);
  EXPECT_EQ(b.report.clips, 6);
  EXPECT_EQ(b.report.inputs, 5);
  EXPECT_TRUE(b.report.refused.empty());
  EXPECT_FLOAT_EQ(db.frame_time, 1.0f / 30.0f);
  int expected_frames = 0, expected_searchable = 0;
  for (size_t c = 0; c < 5; ++c) {
    const ClipRange& range = db.clips[c];
    EXPECT_EQ(range.name, kClips[c]);
    EXPECT_FALSE(range.mirrored);
    EXPECT_EQ(range.start, expected_frames) << "clips tile the frames in order";
    EXPECT_EQ(range.frame_count(), b.sources[c].frame_count) << range.name;
    int searchable = 0;
    for (int f = range.start; f < range.end; ++f) {
      searchable += db.searchable[f];
      EXPECT_EQ(db.frame_clip[f], static_cast<int>(c));
    }
    EXPECT_EQ(searchable, range.frame_count() - 30) << range.name;
    // The excluded frames are exactly the last 30.
    EXPECT_EQ(db.searchable[range.end - 31], 1);
    EXPECT_EQ(db.searchable[range.end - 30], 0);
    expected_frames += range.frame_count();
    expected_searchable += range.frame_count() - 30;
  }
  const ClipRange& idle = db.clips[5];
  EXPECT_EQ(idle.name, "idle");
  EXPECT_EQ(idle.start, expected_frames);
  EXPECT_EQ(idle.frame_count(), 90);
  EXPECT_EQ(b.report.idle_frames, 90);
  expected_frames += 90;
  expected_searchable += 90 - 30;
  EXPECT_EQ(db.frame_count, expected_frames);
  EXPECT_EQ(b.report.frames, expected_frames);
  EXPECT_EQ(b.report.searchable_frames, expected_searchable);
  EXPECT_NEAR(b.report.duration_s, expected_frames / 30.0, 1e-6);
  EXPECT_GT(b.report.bytes_read, 1000000u);
}

TEST(BuilderRealClips, SkeletonRolesAndSimulationRootOnTheGround) {
  const DatabaseView db = *built().db;
  ASSERT_EQ(db.joint_count(), 23);
  EXPECT_EQ(db.skeleton.name(0), "Simulation");
  EXPECT_EQ(db.skeleton.name(1), "joint_Root");
  EXPECT_EQ(db.skeleton.name(2), "Hips");
  EXPECT_EQ(db.skeleton.parent(1), 0);
  EXPECT_EQ(db.roles.hips, 2);
  EXPECT_EQ(db.roles.left_foot, db.skeleton.find("Foot_L"));
  EXPECT_EQ(db.roles.right_foot, db.skeleton.find("Foot_R"));
  EXPECT_EQ(db.roles.left_toe, db.skeleton.find("Toes_L"));
  EXPECT_EQ(db.roles.head, db.skeleton.find("Head"));
  for (int f = 0; f < db.frame_count; ++f) {
    ASSERT_EQ(db.local_positions[static_cast<size_t>(f) * 23].y, 0.0f) << f;
  }
  // Globals are those of the source files (the re-rooting changes no world transform).
  const Built& b = built();
  for (size_t c = 0; c < 5; ++c) {
    for (int f = 0; f < b.sources[c].frame_count; f += 17) {
      const std::vector<Transform> s = source_globals(b.sources[c], f);
      const std::vector<Transform> d = test::frame_globals(db, db.clips[c].start + f);
      for (int j = 0; j < 22; ++j) {
        EXPECT_NEAR(glm::distance(s[j].translation, d[j + 1].translation), 0.0f, 1e-4f);
      }
    }
  }
}

TEST(BuilderRealClips, FacingFollowsTheTravelDirectionOnAWalk) {
  // Travel direction from the source hips over the next second, computed independently.
  const Built& b = built();
  const Clip& walk = b.sources[0];
  const ClipRange& range = b.db->clips()[0];
  const int hips = walk.skeleton.find("Hips");
  int checked = 0;
  float worst = 0.0f;
  for (int f = 0; f + 30 < walk.frame_count; ++f) {
    glm::vec3 travel =
        source_globals(walk, f + 30)[hips].translation - source_globals(walk, f)[hips].translation;
    travel.y = 0.0f;
    if (glm::length(travel) < 0.5f) continue;  // standing: no travel direction
    const glm::vec3 facing =
        b.db->local_rotations()[static_cast<size_t>(range.start + f) * 23] * glm::vec3(0, 0, 1);
    EXPECT_NEAR(facing.y, 0.0f, 1e-5f);
    const float cosine = glm::dot(glm::normalize(travel), glm::normalize(facing));
    worst = std::max(worst, std::acos(std::clamp(cosine, -1.0f, 1.0f)));
    ++checked;
  }
  EXPECT_GT(checked, walk.frame_count / 2);
  EXPECT_LT(worst, 15.0f * 3.14159265f / 180.0f) << "worst angle (rad) " << worst;
}

TEST(BuilderRealClips, WalkContactsArePlausibleAndFeetAreStillWhileInContact) {
  const Built& b = built();
  const Clip& walk = b.sources[0];
  const ClipRange& range = b.db->clips()[0];
  const int n = walk.frame_count;
  const char* feet[] = {"Foot_L", "Foot_R"};
  for (int side = 0; side < 2; ++side) {
    const int foot = walk.skeleton.find(feet[side]);
    int in_contact = 0;
    double speed_in = 0.0, speed_out = 0.0;
    for (int f = 1; f + 1 < n; ++f) {
      glm::vec3 d = source_globals(walk, f + 1)[foot].translation -
                    source_globals(walk, f - 1)[foot].translation;
      d.y = 0.0f;
      const double speed = glm::length(d) * 15.0;  // central difference over 2 / 30 s
      if (b.db->contacts()[static_cast<size_t>(range.start + f) * 2 + side]) {
        ++in_contact;
        speed_in += speed;
      } else {
        speed_out += speed;
      }
    }
    const double fraction = in_contact / static_cast<double>(n - 2);
    EXPECT_GT(fraction, 0.3) << feet[side];
    EXPECT_LT(fraction, 0.8) << feet[side];
    const double mean_in = speed_in / in_contact;
    const double mean_out = speed_out / (n - 2 - in_contact);
    EXPECT_LT(mean_in, 0.25) << feet[side] << " slides while in contact";
    EXPECT_GT(mean_out, 4.0 * mean_in) << feet[side];
  }
  // The wave stands on both feet all the time.
  const ClipRange& wave = b.db->clips()[4];
  int both = 0;
  for (int f = wave.start; f < wave.end; ++f)
    both += b.db->contacts()[f * 2] & b.db->contacts()[f * 2 + 1];
  EXPECT_GT(both, wave.frame_count() * 9 / 10);
}

TEST(BuilderRealClips, FeaturesAreFiniteNormalizedAndTagsFollowTheNames) {
  const DatabaseView db = *built().db;
  ASSERT_EQ(db.feature_dims(), 27);
  ASSERT_EQ(db.features.size(), static_cast<size_t>(db.frame_count) * 27);
  for (float x : db.features) ASSERT_TRUE(std::isfinite(x));
  for (int c = 0; c < 27; ++c) {
    EXPECT_TRUE(std::isfinite(db.feature_offset[c]));
    EXPECT_GT(db.feature_scale[c], 0.0f);
  }
  // Searchable rows are normalized to zero mean per column.
  for (int c = 0; c < 27; ++c) {
    double sum = 0.0;
    int count = 0;
    for (int f = 0; f < db.frame_count; ++f) {
      if (!db.searchable[f]) continue;
      sum += db.features[static_cast<size_t>(f) * 27 + c];
      ++count;
    }
    EXPECT_NEAR(sum / count, 0.0, 1e-3) << c;
  }
  EXPECT_TRUE(std::is_sorted(db.tag_names.begin(), db.tag_names.end()));
  EXPECT_TRUE(has_tag(db, db.clips[0], "walk"));
  EXPECT_TRUE(has_tag(db, db.clips[0], "normal"));
  EXPECT_TRUE(has_tag(db, db.clips[0], "locomotion"));
  EXPECT_FALSE(has_tag(db, db.clips[0], "action"));
  EXPECT_TRUE(has_tag(db, db.clips[2], "walk-turn-left"));
  EXPECT_TRUE(has_tag(db, db.clips[3], "run"));
  EXPECT_TRUE(has_tag(db, db.clips[4], "action"));
  EXPECT_TRUE(has_tag(db, db.clips[4], "wave-both-hands"));
  EXPECT_FALSE(has_tag(db, db.clips[4], "locomotion"));
}

TEST(BuilderRealClips, MirroredBuildDoublesTheClipsAndMirrorsTheFeatures) {
  const std::vector<fs::path> paths = {test::clip_path(kClips[2]), test::clip_path(kClips[3])};
  BuildOptions options;
  options.mirror = true;
  options.idle_seconds = 0.0f;  // the mirrored copies only
  BuildReport report;
  Result<Database> db = build_database(paths, options, &report);
  ASSERT_TRUE(db) << db.message();
  ASSERT_EQ(db->clips().size(), 4u);
  EXPECT_EQ(report.clips, 4);
  EXPECT_EQ(db->clips()[1].name, std::string(kClips[2]) + "_mirror");
  EXPECT_TRUE(db->clips()[1].mirrored);
  EXPECT_FALSE(db->clips()[0].mirrored);
  EXPECT_EQ(db->clips()[1].frame_count(), db->clips()[0].frame_count());
  EXPECT_TRUE(has_tag(*db, db->clips()[1], "mirrored"));
  EXPECT_TRUE(has_tag(*db, db->clips()[1], "walk-turn-right"));
  EXPECT_FALSE(has_tag(*db, db->clips()[1], "walk-turn-left"));
  EXPECT_FALSE(has_tag(*db, db->clips()[0], "mirrored"));

  // Raw features of a mirrored frame: left and right feet swap, x flips; trajectory x flips.
  std::vector<float> raw(db->features().begin(), db->features().end());
  denormalize_features(raw, db->feature_offset(), db->feature_scale());
  const ClipRange& a = db->clips()[0];
  const ClipRange& m = db->clips()[1];
  for (int f = 0; f < a.frame_count(); f += 5) {
    const float* o = raw.data() + static_cast<size_t>(a.start + f) * 27;
    const float* r = raw.data() + static_cast<size_t>(m.start + f) * 27;
    for (int k = 0; k < 3; ++k) {
      const float sign = k == 0 ? -1.0f : 1.0f;
      EXPECT_NEAR(r[0 + k], sign * o[3 + k], 1e-4f) << f;  // left foot <- right foot
      EXPECT_NEAR(r[3 + k], sign * o[0 + k], 1e-4f) << f;
      EXPECT_NEAR(r[6 + k], sign * o[9 + k], 1e-3f) << f;  // velocities
      EXPECT_NEAR(r[12 + k], sign * o[12 + k], 1e-3f) << f;
    }
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(r[15 + 2 * k], -o[15 + 2 * k], 1e-4f) << f;
      EXPECT_NEAR(r[16 + 2 * k], o[16 + 2 * k], 1e-4f) << f;
      EXPECT_NEAR(r[21 + 2 * k], -o[21 + 2 * k], 1e-4f) << f;
      EXPECT_NEAR(r[22 + 2 * k], o[22 + 2 * k], 1e-4f) << f;
    }
    // Contacts swap sides.
    EXPECT_EQ(db->contacts()[(m.start + f) * 2], db->contacts()[(a.start + f) * 2 + 1]) << f;
  }
}

TEST(BuilderThreads, OutputDoesNotDependOnTheThreadCount) {
  // With mirrored copies and the idle clip, whose source frame is searched for after the
  // parallel phase and whose features are normalized with the rest.
  std::vector<Database> dbs;
  std::vector<BuildReport> reports;
  for (const int threads : {1, 2, 3}) {
    BuildOptions options;
    options.threads = threads;
    options.mirror = true;
    BuildReport report;
    Result<Database> db = build_database(clip_paths(), options, &report);
    ASSERT_TRUE(db) << db.message();
    EXPECT_EQ(report.threads, threads);
    ASSERT_EQ(find_idle_clip(*db), static_cast<int>(db->clips().size()) - 1);
    dbs.push_back(std::move(db).value());
    reports.push_back(report);
  }
  for (size_t i = 1; i < dbs.size(); ++i) {
    const DatabaseView a = dbs[0];
    const DatabaseView b = dbs[i];
    ASSERT_EQ(a.frame_count, b.frame_count);
    EXPECT_EQ(reports[0].idle_source_clip, reports[i].idle_source_clip);
    EXPECT_EQ(reports[0].idle_source_frame, reports[i].idle_source_frame);
    ASSERT_EQ(a.clips.size(), b.clips.size());
    for (size_t c = 0; c < a.clips.size(); ++c) {
      EXPECT_EQ(a.clips[c].name, b.clips[c].name);
      EXPECT_EQ(a.clips[c].start, b.clips[c].start);
      EXPECT_EQ(a.clips[c].tags, b.clips[c].tags);
    }
    // The pose, bit for bit: every frame's lanes (the four quantities of every joint).
    ASSERT_EQ(dbs[0].pose_lanes().size(), dbs[i].pose_lanes().size());
    EXPECT_EQ(0, std::memcmp(dbs[0].pose_lanes().data(), dbs[i].pose_lanes().data(),
                             dbs[0].pose_lanes().size_bytes()));
    EXPECT_TRUE(std::ranges::equal(a.searchable, b.searchable));
    EXPECT_TRUE(std::ranges::equal(a.feature_offset, b.feature_offset));
    EXPECT_EQ(0, std::memcmp(a.features.data(), b.features.data(), a.features.size() * 4));
    EXPECT_TRUE(std::ranges::equal(a.contacts, b.contacts));
    EXPECT_TRUE(std::ranges::equal(a.feature_scale, b.feature_scale));
    EXPECT_TRUE(std::ranges::equal(a.tag_names, b.tag_names));
  }
}

// ---- Bad inputs --------------------------------------------------------------------------------

TEST(BuilderBadInputs, BrokenFileIsNamedAndSkippedOnRequest) {
  const fs::path dir = test::scratch_dir();
  fs::copy_file(test::clip_path(kClips[0]), dir / "a_walk.bvh");
  fs::copy_file(test::clip_path(kClips[3]), dir / "c_run.bvh");
  std::ofstream(dir / "b_broken.bvh") << "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0\n";
  std::ofstream(dir / "notes.txt") << "not motion";  // ignored: not a motion file extension
  const fs::path inputs[] = {dir};

  Result<Database> db = build_database(inputs, BuildOptions{});
  ASSERT_FALSE(db);
  EXPECT_NE(db.message().find("b_broken.bvh"), std::string::npos) << db.message();

  BuildOptions skip;
  skip.skip_bad = true;
  skip.idle_seconds = 0.0f;  // the clips of the good files only
  BuildReport report;
  db = build_database(inputs, skip, &report);
  ASSERT_TRUE(db) << db.message();
  ASSERT_EQ(db->clips().size(), 2u);
  EXPECT_EQ(db->clips()[0].name, "a_walk");
  EXPECT_EQ(db->clips()[1].name, "c_run");
  EXPECT_EQ(report.inputs, 3);
  ASSERT_EQ(report.refused.size(), 1u);
  EXPECT_EQ(report.refused[0].path.filename(), "b_broken.bvh");
  EXPECT_NE(report.refused[0].message.find("b_broken.bvh"), std::string::npos);
}

TEST(BuilderMixedSkeletons, AnotherSkeletonIsRetargetedOntoTheFirst) {
  const fs::path dir = test::scratch_dir();
  fs::copy_file(test::clip_path(kClips[0]), dir / "a_walk.bvh");
  std::ofstream(dir / "z_other.bvh") << other_skeleton_bvh();
  const fs::path inputs[] = {dir};
  BuildOptions options;
  options.idle_seconds = 0.0f;
  BuildReport report;
  Result<Database> db = build_database(inputs, options, &report);
  ASSERT_TRUE(db) << db.message();
  ASSERT_EQ(db->clips().size(), 2u);
  EXPECT_EQ(db->joint_count(), 23);  // the Bandai skeleton and the simulation root
  ASSERT_EQ(report.retargeted.size(), 1u);
  EXPECT_NE(report.retargeted[0].find("z_other.bvh: 1 clip(s) retargeted"), std::string::npos)
      << report.retargeted[0];
  // The other skeleton has no arms, spine or toes: those Bandai joints stay at rest.
  EXPECT_NE(report.retargeted[0].find("UpperArm_L"), std::string::npos) << report.retargeted[0];

  // A skeleton whose legs cannot be found is refused, naming the file and the role.
  std::ofstream(dir / "zz_legless.bvh")
      << "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 90 0\n  CHANNELS 3 Xposition Yposition "
         "Zposition\n  JOINT LeftFoot\n  {\n    OFFSET 10 -80 0\n    CHANNELS 0\n  }\n  JOINT "
         "RightFoot\n  {\n    OFFSET -10 -80 0\n    CHANNELS 0\n  }\n}\nMOTION\nFrames: 2\n"
         "Frame Time: 0.0333333\n0 90 0\n0 90 1\n";
  db = build_database(inputs, options, &report);
  ASSERT_FALSE(db);
  EXPECT_NE(db.message().find("zz_legless.bvh"), std::string::npos) << db.message();
  EXPECT_NE(db.message().find("required role 'left_upper_leg'"), std::string::npos) << db.message();
}

// BuildOptions::target: the database takes its skeleton (not the first input's) and its roles,
// every input is retargeted onto it, and its own frames stay out of the database.
TEST(BuilderMixedSkeletons, ATargetSkeletonIsTheDatabasesAndTakesItsRoles) {
  Result<Clip> target =
      load_bvh(test::mocap_dir() / "reactidle" / "genuine" / "000_genuine.bvh", BvhOptions{0.0f});
  ASSERT_TRUE(target) << target.message();
  const fs::path inputs[] = {test::clip_path(kClips[0])};
  BuildOptions options;
  options.idle_seconds = 0.0f;
  options.target = *target;
  BuildReport report;
  Result<Database> db = build_database(inputs, options, &report);
  ASSERT_TRUE(db) << db.message();
  ASSERT_EQ(db->clips().size(), 1u);
  EXPECT_EQ(db->clips()[0].name, kClips[0]);
  ASSERT_EQ(db->joint_count(), target->joint_count() + 1);
  for (int j = 0; j < target->joint_count(); ++j) {
    EXPECT_EQ(db->skeleton().name(j + 1), target->skeleton.name(j));
    EXPECT_EQ(db->skeleton().rest(j + 1).translation, target->skeleton.rest(j).translation);
  }
  EXPECT_EQ(db->roles().hips, 1);  // "pelvis", behind the simulation root
  ASSERT_EQ(report.retargeted.size(), 1u);

  // The target's map is checked against the target's skeleton, and its errors name the target.
  options.target_role_map = {{"head", "Skull", 2, "rig.map"}};
  db = build_database(inputs, options, &report);
  ASSERT_FALSE(db);
  EXPECT_NE(db.message().find("target "), std::string::npos) << db.message();
  EXPECT_NE(db.message().find("rig.map:2: head=Skull: no joint named 'Skull'"), std::string::npos)
      << db.message();
}

// The database stands on y = 0. ReActIdle's people stand 0.7 to 1 m below their root (at y = 0);
// on their skeleton, the take and a walk retargeted onto it (which stands on the take's ground)
// are moved up, each to put its lowest foot end on y = 0. Bandai's clips, whose toes reach
// 2.5 cm above y = 0, are left where they are.
TEST(BuilderMixedSkeletons, DataOnAnotherGroundIsMovedToStandOnYZero) {
  const fs::path inputs[] = {test::mocap_dir() / "reactidle" / "genuine" / "000_genuine.bvh",
                             test::clip_path(kClips[0])};
  BuildOptions options;
  options.bvh.scale = 0.0f;  // centimetres and metres
  BuildReport report;
  Result<Database> db = build_database(inputs, options, &report);
  ASSERT_TRUE(db) << db.message();
  EXPECT_EQ(report.ground_summary.rfind("2 clip(s) whose feet never came within 0.15 m of y = 0 "
                                        "moved by +0.",
                                        0),
            0u)
      << report.ground_summary;
  const size_t joints = static_cast<size_t>(db->joint_count());
  std::vector<Transform> local(joints), global(joints);
  for (const ClipRange& clip : db->clips()) {
    float lowest = std::numeric_limits<float>::infinity();
    for (int f = clip.start; f < clip.end; ++f) {
      for (size_t j = 0; j < joints; ++j) {
        local[j].translation = db->local_positions()[static_cast<size_t>(f) * joints + j];
        local[j].rotation = db->local_rotations()[static_cast<size_t>(f) * joints + j];
      }
      forward_kinematics(db->skeleton().parents(), local, global);
      for (const int foot : {db->roles().left_foot, db->roles().right_foot}) {
        lowest = std::min(lowest, global[static_cast<size_t>(foot)].translation.y);
      }
    }
    // The ankles (this skeleton has no toes) stand a few centimetres above the ground.
    EXPECT_GT(lowest, 0.0f) << clip.name;
    EXPECT_LT(lowest, 0.15f) << clip.name;
  }

  const fs::path bandai[] = {test::clip_path(kClips[0])};
  BuildReport untouched;
  ASSERT_TRUE(build_database(bandai, BuildOptions{}, &untouched));
  EXPECT_EQ(untouched.ground_summary, "");
}

// Real idle clips (ReActIdle, on another skeleton) are retargeted, cut into calm segments,
// tagged idle, stand still at joint 0 and replace the synthesized held-frame idle clip.
TEST(BuilderMixedSkeletons, ReActIdleClipsBecomeStillStandingIdleClips) {
  const fs::path inputs[] = {test::clip_path(kClips[0]),
                             test::mocap_dir() / "reactidle" / "genuine" / "000_genuine.bvh"};
  BuildOptions options;
  options.bvh.scale = 0.0f;  // centimetres and metres
  BuildReport report;
  Result<Database> db = build_database(inputs, options, &report);
  ASSERT_TRUE(db) << db.message();
  ASSERT_GE(db->clips().size(), 2u);
  EXPECT_EQ(report.idle_frames, 0);  // no synthesized idle clip
  EXPECT_NE(report.idle_summary.find("1 idle takes"), std::string::npos) << report.idle_summary;
  for (size_t c = 1; c < db->clips().size(); ++c) {
    EXPECT_EQ(db->clips()[c].name.rfind("000_genuine_at", 0), 0u) << db->clips()[c].name;
  }
  const ClipRange& idle = db->clips()[1];
  EXPECT_NE(idle.tags & db->tag_mask(std::vector<std::string>{"idle"}), 0u);
  const size_t joints = static_cast<size_t>(db->joint_count());
  const size_t first = static_cast<size_t>(idle.start) * joints;
  for (int f = idle.start; f < idle.end; f += 50) {
    const size_t at = static_cast<size_t>(f) * joints;
    EXPECT_EQ(db->local_positions()[at], db->local_positions()[first]) << f;
    EXPECT_EQ(db->local_rotations()[at], db->local_rotations()[first]) << f;
  }
  // The walk's joint 0 moves.
  EXPECT_NE(db->local_positions()[0], db->local_positions()[joints * 30]);
}

TEST(BuilderBadInputs, MissingPathsEmptyFoldersAndBadOptions) {
  const fs::path dir = test::scratch_dir();
  const fs::path missing[] = {dir / "nope"};
  Result<Database> db = build_database(missing, BuildOptions{});
  ASSERT_FALSE(db);
  EXPECT_NE(db.message().find("nope"), std::string::npos);

  const fs::path empty[] = {dir};
  db = build_database(empty, BuildOptions{});
  ASSERT_FALSE(db);
  EXPECT_NE(db.message().find("no .bvh"), std::string::npos) << db.message();

  const fs::path one[] = {test::clip_path(kClips[4])};
  BuildOptions bad_rate;
  bad_rate.rate = 0.0f;
  EXPECT_FALSE(build_database(one, bad_rate));
  BuildOptions bad_schema;
  bad_schema.schema.channels[0].weight = -1.0f;
  EXPECT_FALSE(build_database(one, bad_schema));
  BuildOptions bad_tags;
  bad_tags.tags_file = dir / "missing.tags";
  db = build_database(one, bad_tags);
  ASSERT_FALSE(db);
  EXPECT_NE(db.message().find("missing.tags"), std::string::npos);
  BuildOptions no_feet;
  no_feet.roles.left_foot = {"Ankle_Left"};
  db = build_database(one, no_feet);
  ASSERT_FALSE(db);
  EXPECT_NE(db.message().find("left_foot"), std::string::npos) << db.message();
  EXPECT_NE(db.message().find("Ankle_Left"), std::string::npos) << db.message();
}

TEST(BuilderBadInputs, TooManyTags) {
  const fs::path dir = test::scratch_dir();
  std::string manifest = "* ";
  for (int i = 0; i < 70; ++i) manifest += " t" + std::to_string(i);
  std::ofstream(dir / "many.tags") << manifest << "\n";
  const fs::path one[] = {test::clip_path(kClips[4])};
  BuildOptions options;
  options.tags_file = dir / "many.tags";
  Result<Database> db = build_database(one, options);
  ASSERT_FALSE(db);
  EXPECT_NE(db.message().find("at most 64"), std::string::npos) << db.message();
}

// ---- In memory, options ------------------------------------------------------------------------

TEST(BuilderOptions, RateManifestAndProgress) {
  const fs::path dir = test::scratch_dir();
  std::ofstream(dir / "demo.tags") << "# demo\n*_run_* fast\n*wave* hello greeting\n";
  BuildOptions options;
  options.rate = 60.0f;
  options.tags_file = dir / "demo.tags";
  size_t calls = 0, last_done = 0, last_total = 0;
  options.progress = [&](size_t done, size_t total) {
    ++calls;
    EXPECT_GT(done, last_done);
    last_done = done;
    last_total = total;
  };
  const fs::path inputs[] = {test::clip_path(kClips[3]), test::clip_path(kClips[4])};
  BuildReport report;
  Result<Database> db = build_database(inputs, options, &report);
  ASSERT_TRUE(db) << db.message();
  // Each input counts twice: imported, then processed.
  EXPECT_EQ(calls, 4u);
  EXPECT_EQ(last_done, 4u);
  EXPECT_EQ(last_total, 4u);
  EXPECT_FLOAT_EQ(db->frame_time(), 1.0f / 60.0f);
  const Built& b = built();
  // At 60 Hz a clip of n frames at 30 Hz becomes 2n - 1 frames; 1 s of features is 60 frames.
  for (int c = 0; c < 2; ++c) {
    const int n = b.sources[3 + c].frame_count;
    EXPECT_EQ(db->clips()[c].frame_count(), 2 * n - 1);
    int searchable = 0;
    for (int f = db->clips()[c].start; f < db->clips()[c].end; ++f)
      searchable += db->searchable()[f];
    EXPECT_EQ(searchable, 2 * n - 1 - 60);
  }
  EXPECT_TRUE(has_tag(*db, db->clips()[0], "fast"));
  EXPECT_FALSE(has_tag(*db, db->clips()[0], "hello"));
  EXPECT_TRUE(has_tag(*db, db->clips()[1], "hello"));
  EXPECT_TRUE(has_tag(*db, db->clips()[1], "greeting"));
}

TEST(BuilderOptions, InMemoryClipsAndSingleClipWarnings) {
  // One clip that never turns: the trajectory direction channel has no deviation.
  Clip clip;
  clip.name = "straight";
  Result<Skeleton> sk = Skeleton::create(
      {"Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "RightUpLeg", "RightLeg", "RightFoot"},
      {-1, 0, 1, 2, 0, 4, 5}, std::vector<Transform>(7));
  ASSERT_TRUE(sk);
  clip.skeleton = *sk;
  clip.frame_count = 60;
  for (int f = 0; f < 60; ++f) {
    Transform hips;
    hips.translation = {0.0f, 0.9f, f * 0.04f};
    Transform left, right, at_parent;  // the upper and lower legs sit at the hips
    left.translation = {0.1f, -0.85f, 0.0f};
    right.translation = {-0.1f, -0.85f, 0.0f};
    clip.local.insert(clip.local.end(),
                      {hips, at_parent, at_parent, left, at_parent, at_parent, right});
  }
  BuildReport report;
  Result<Database> db = build_database_from_clips(std::span(&clip, 1), BuildOptions{}, &report);
  ASSERT_TRUE(db) << db.message();
  EXPECT_EQ(db->frame_count(), 60);
  bool warned = false;
  for (const std::string& w : report.warnings) {
    if (w.find("trajectory_direction") != std::string::npos) warned = true;
  }
  EXPECT_TRUE(warned);
  for (float x : db->features()) ASSERT_TRUE(std::isfinite(x));
}

TEST(BuilderOptions, ClipsTooShortToMatchAreReported) {
  // The normal-style set-1 dash has 20 frames, less than the 1 s the trajectory needs.
  const fs::path inputs[] = {test::clip_path("dataset-1_dash_normal_001"),
                             test::clip_path("dataset-1_walk_normal_001")};
  BuildOptions options;
  options.idle_seconds = 0.0f;  // its frames and any warning about it are not the subject here
  BuildReport report;
  Result<Database> db = build_database(inputs, options, &report);
  ASSERT_TRUE(db) << db.message();
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("dataset-1_dash_normal_001"), std::string::npos);
  EXPECT_EQ(report.searchable_frames, db->clips()[1].frame_count() - 30);
}

// A BVH file with one frame line more than it declares (as assimp's Boxing_Toes.bvh): its
// import warning leads BuildReport::warnings, once, from a file and from an in-memory clip.
TEST(BuilderOptions, ImportWarningsOfTheClipsReachTheReport) {
  const fs::path dir = test::scratch_dir();
  const fs::path path = dir / "walk_extra_line.bvh";
  std::string text;
  {
    std::ifstream in(test::clip_path(kClips[0]), std::ios::binary);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  ASSERT_EQ(text.back(), '\n');
  const size_t last_line = text.rfind('\n', text.size() - 2) + 1;
  text += text.substr(last_line);  // the last frame line again
  std::ofstream(path, std::ios::binary) << text;
  const int first_ignored_line = static_cast<int>(std::count(text.begin(), text.end(), '\n'));
  const int frames_line =
      1 + static_cast<int>(std::count(text.begin(), text.begin() + text.find("Frames:"), '\n'));
  const std::string warning = path.string() + ":" + std::to_string(first_ignored_line) +
                              ": ignored 1 frame line beyond 'Frames: 273' on line " +
                              std::to_string(frames_line);

  BuildOptions options;
  options.idle_seconds = 0.0f;  // the build's own warnings are not the subject here
  const fs::path inputs[] = {path};
  BuildReport report;
  Result<Database> db = build_database(inputs, options, &report);
  ASSERT_TRUE(db) << db.message();
  EXPECT_EQ(db->frame_count(), 273);
  ASSERT_FALSE(report.warnings.empty());
  EXPECT_EQ(report.warnings[0], warning);
  EXPECT_EQ(std::count(report.warnings.begin(), report.warnings.end(), warning), 1);

  Result<Clip> clip = load_bvh(path);
  ASSERT_TRUE(clip) << clip.message();
  ASSERT_EQ(clip->warnings, std::vector<std::string>{warning});
  db = build_database_from_clips(std::span(&*clip, 1), options, &report);
  ASSERT_TRUE(db) << db.message();
  ASSERT_FALSE(report.warnings.empty());
  EXPECT_EQ(report.warnings[0], warning);
  EXPECT_EQ(std::count(report.warnings.begin(), report.warnings.end(), warning), 1);
}

TEST(BuilderOptions, GltfInputBuildsLikeTheBvhItCameFrom) {
  // The walk written as .glb (metres, 30 Hz) and read back through the glTF importer gives
  // the same database as the BVH itself.
  const fs::path dir = test::scratch_dir();
  Result<Clip> walk = load_bvh(test::clip_path(kClips[0]));
  ASSERT_TRUE(walk) << walk.message();
  ASSERT_TRUE(save_gltf(*walk, dir / "walk.glb"));
  const fs::path from_gltf[] = {dir / "walk.glb"};
  const fs::path from_bvh[] = {test::clip_path(kClips[0])};
  Result<Database> a = build_database(from_gltf, BuildOptions{});
  ASSERT_TRUE(a) << a.message();
  Result<Database> b = build_database(from_bvh, BuildOptions{});
  ASSERT_TRUE(b) << b.message();
  ASSERT_EQ(a->frame_count(), b->frame_count());
  ASSERT_EQ(a->joint_count(), b->joint_count());
  EXPECT_EQ(a->skeleton().names(), b->skeleton().names());
  ASSERT_EQ(a->features().size(), b->features().size());
  std::vector<float> raw_a(a->features().begin(), a->features().end());
  std::vector<float> raw_b(b->features().begin(), b->features().end());
  denormalize_features(raw_a, a->feature_offset(), a->feature_scale());
  denormalize_features(raw_b, b->feature_offset(), b->feature_scale());
  for (size_t i = 0; i < raw_a.size(); ++i) ASSERT_NEAR(raw_a[i], raw_b[i], 1e-3f) << i;
  EXPECT_TRUE(std::ranges::equal(a->contacts(), b->contacts()));
}

// ---- End to end --------------------------------------------------------------------------------

TEST(BuilderEndToEnd, BuildSaveLoadAndRecomputeTheSameFeatures) {
  const DatabaseView db = *built().db;
  const fs::path file = test::scratch_dir() / "five.mmdb";
  ASSERT_TRUE(save_database(*built().db, file));
  Result<Database> loaded = load_database(file);
  ASSERT_TRUE(loaded) << loaded.message();
  EXPECT_TRUE(std::ranges::equal(loaded->features(), db.features));
  EXPECT_TRUE(std::ranges::equal(loaded->feature_offset(), db.feature_offset));
  EXPECT_TRUE(std::ranges::equal(loaded->feature_scale(), db.feature_scale));
  EXPECT_TRUE(std::ranges::equal(loaded->searchable(), db.searchable));
  EXPECT_TRUE(std::ranges::equal(loaded->contacts(), db.contacts));
  ASSERT_EQ(loaded->clips().size(), db.clips.size());
  for (size_t c = 0; c < db.clips.size(); ++c) {
    EXPECT_EQ(loaded->clips()[c].name, db.clips[c].name);
    EXPECT_EQ(loaded->clips()[c].start, db.clips[c].start);
    EXPECT_EQ(loaded->clips()[c].tags, db.clips[c].tags);
  }
  // Recomputing the features from the loaded motion arrays finds the same matrix.
  DatabaseContents recomputed = loaded->contents();
  recomputed.features.clear();
  ASSERT_TRUE(compute_database_features(recomputed));
  ASSERT_EQ(recomputed.features.size(), db.features.size());
  for (size_t i = 0; i < db.features.size(); ++i) {
    ASSERT_NEAR(recomputed.features[i], db.features[i], 1e-4f) << i;
  }
  EXPECT_TRUE(std::ranges::equal(recomputed.searchable, db.searchable));
}

}  // namespace
}  // namespace mm
