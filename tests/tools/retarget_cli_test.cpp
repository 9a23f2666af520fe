// `mm retarget` and `mm build --target` as scripts use them: real clips of the Bandai and
// ReActIdle skeletons moved onto each other, checked by reading the written files back.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "mm/database/database_file.hpp"
#include "mm/offline/bvh.hpp"
#include "mm/offline/gltf.hpp"
#include "mm/runtime/pose.hpp"
#include "run_tool.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

namespace fs = std::filesystem;

using test::CommandRun;
using test::quoted;
using test::run_mm;

fs::path bandai_walk() {
  return test::clip_path("dataset-2_walk_normal_001");
}
fs::path reactidle_clip() {
  return test::mocap_dir() / "reactidle" / "genuine" / "000_genuine.bvh";
}

// A BVH file in its own units (scale 1): what its OFFSET lines say.
Clip in_file_units(const fs::path& path) {
  Result<Clip> clip = load_bvh(path, BvhOptions{1.0f});
  EXPECT_TRUE(clip) << clip.message();
  return clip ? std::move(clip).value() : Clip{};
}

// A BVH file in metres, its units found from its size as the command finds them.
Clip in_metres(const fs::path& path) {
  Result<Clip> clip = load_bvh(path, BvhOptions{0.0f});
  EXPECT_TRUE(clip) << clip.message();
  return clip ? std::move(clip).value() : Clip{};
}

// Same joint names in the same order, same parents, rest translations within `tolerance`.
void expect_same_skeleton(const Skeleton& got, const Skeleton& want, float tolerance) {
  ASSERT_EQ(got.joint_count(), want.joint_count());
  EXPECT_EQ(got.names(), want.names());
  EXPECT_EQ(got.parents(), want.parents());
  for (int j = 0; j < want.joint_count(); ++j) {
    EXPECT_LE(glm::length(got.rest(j).translation - want.rest(j).translation), tolerance)
        << want.name(j);
  }
}

size_t count_lines_starting(const std::string& text, const std::string& prefix) {
  size_t count = 0;
  for (size_t at = text.find(prefix); at != std::string::npos; at = text.find(prefix, at + 1)) {
    if (at == 0 || text[at - 1] == '\n') ++count;
  }
  return count;
}

CommandRun retarget(const fs::path& source, const fs::path& target, const fs::path& out,
                    const std::string& more = "") {
  return run_mm("retarget " + quoted(source) + " --to " + quoted(target) + " -o " + quoted(out) +
                more);
}

// The written file has the target's skeleton exactly (its OFFSETs as the file states them) and
// the source's frames and frame time, and the command says what it matched.
void expect_retargeted_file(const fs::path& source, const fs::path& target, const fs::path& out) {
  const CommandRun run = retarget(source, target, out);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_GE(count_lines_starting(run.output, "matched:"), 10u) << run.output;
  EXPECT_NE(run.output.find("matched:      hips: "), std::string::npos) << run.output;
  EXPECT_EQ(count_lines_starting(run.output, "left at rest:"), 1u) << run.output;
  const Clip written = in_file_units(out);
  const Clip wanted = in_file_units(target);
  expect_same_skeleton(written.skeleton, wanted.skeleton, 0.0f);
  EXPECT_EQ(written.end_sites, wanted.end_sites);
  const Clip from = in_file_units(source);
  EXPECT_EQ(written.frame_count, from.frame_count);
  EXPECT_FLOAT_EQ(written.frame_time, from.frame_time);
}

TEST(RetargetCli, BandaiOntoReActIdleAndBackHaveTheTargetSkeletonAndTheSourceFrames) {
  const fs::path dir = test::scratch_dir();
  expect_retargeted_file(bandai_walk(), reactidle_clip(), dir / "walk_on_reactidle.bvh");
  expect_retargeted_file(reactidle_clip(), bandai_walk(), dir / "idle_on_bandai.bvh");
  // Loaded in metres, the two results stand on their targets' skeletons in metres too: the
  // Bandai one was written in centimetres.
  expect_same_skeleton(in_metres(dir / "idle_on_bandai.bvh").skeleton,
                       in_metres(bandai_walk()).skeleton, 1e-6f);
}

TEST(RetargetCli, AClipOntoItsOwnFileKeepsItsGlobalPositions) {
  const fs::path dir = test::scratch_dir();
  const fs::path out = dir / "self.bvh";
  const CommandRun run = retarget(bandai_walk(), bandai_walk(), out);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const Clip source = in_metres(bandai_walk());
  const Clip back = in_metres(out);
  ASSERT_EQ(back.frame_count, source.frame_count);
  ASSERT_TRUE(back.skeleton.same_topology(source.skeleton));
  const size_t joints = static_cast<size_t>(source.joint_count());
  std::vector<Transform> want(joints), got(joints);
  float worst = 0.0f;
  for (int f = 0; f < source.frame_count; ++f) {
    forward_kinematics(source.skeleton.parents(), source.pose(f), want);
    forward_kinematics(back.skeleton.parents(), back.pose(f), got);
    for (size_t j = 0; j < joints; ++j) {
      worst = std::max(worst, glm::length(got[j].translation - want[j].translation));
    }
  }
  std::printf("measure: a clip retargeted onto its own file moves its joints by %.3g m at most\n",
              static_cast<double>(worst));
  EXPECT_LT(worst, 1e-4f);
}

TEST(RetargetCli, AGlbOutputHasTheTargetSkeleton) {
  const fs::path dir = test::scratch_dir();
  const fs::path out = dir / "walk_on_reactidle.glb";
  const CommandRun run = retarget(bandai_walk(), reactidle_clip(), out);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  Result<GltfAsset> asset = load_gltf(out);
  ASSERT_TRUE(asset) << asset.message();
  expect_same_skeleton(asset->skeleton, in_metres(reactidle_clip()).skeleton, 1e-6f);
  ASSERT_EQ(asset->clips.size(), 1u);
  EXPECT_EQ(asset->clips[0].frame_count, in_metres(bandai_walk()).frame_count);
}

TEST(RetargetCli, RateResamplesTheResultOverTheSameDuration) {
  const fs::path dir = test::scratch_dir();
  const fs::path out = dir / "walk_60.bvh";
  const CommandRun run = retarget(bandai_walk(), reactidle_clip(), out, " --rate 60");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const Clip source = in_metres(bandai_walk());
  const Clip written = in_metres(out);
  // The 30 Hz source doubled: one new frame between every two.
  EXPECT_EQ(written.frame_count, 2 * source.frame_count - 1);
  EXPECT_NEAR(written.frame_time, 1.0f / 60.0f, 1e-7f);
  EXPECT_NEAR(written.duration(), source.duration(), 1e-4f);
}

// Debian's assimp-testmodels (installed by scripts/setup.sh): "Frames: 3069" on line 128, then
// 3070 frame lines. Read as Blender and assimp read it, with one warning for the extra line.
TEST(RetargetCli, AFileWithMoreFrameLinesThanDeclaredIsRetargetedWithOneWarning) {
  const fs::path source = "/usr/share/assimp/models/BVH/Boxing_Toes.bvh";
  ASSERT_TRUE(fs::is_regular_file(source))
      << source << " is missing: install Debian's assimp-testmodels (scripts/setup.sh)";
  const fs::path out = test::scratch_dir() / "boxing_on_bandai.bvh";
  const CommandRun run = retarget(source, bandai_walk(), out);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(count_lines_starting(run.output, "mm retarget: warning: "), 1u) << run.output;
  EXPECT_EQ(count_lines_starting(run.output,
                                 "mm retarget: warning: " + source.string() +
                                     ":3199: ignored 1 frame line beyond 'Frames: 3069' on line "
                                     "128\n"),
            1u)
      << run.output;
  EXPECT_EQ(in_file_units(out).frame_count, 3069);
}

TEST(RetargetCli, MistakesAUserCanFixAreNamed) {
  const fs::path dir = test::scratch_dir();
  const fs::path out = dir / "out.bvh";
  const CommandRun far = retarget(bandai_walk(), reactidle_clip(), out, " --rest-frame 100000");
  EXPECT_EQ(far.exit_code, 1) << far.output;
  EXPECT_NE(far.output.find("rest frame 100000 is past its last frame"), std::string::npos)
      << far.output;

  std::ofstream(dir / "bad.map") << "# the source\nhips = Hips\nleft_foot Foot_L\n";
  const CommandRun map =
      retarget(bandai_walk(), reactidle_clip(), out, " --map " + quoted(dir / "bad.map"));
  EXPECT_EQ(map.exit_code, 1) << map.output;
  EXPECT_NE(map.output.find("bad.map:3: expected 'role=Joint'"), std::string::npos) << map.output;

  std::ofstream(dir / "wrong.map") << "left_foot = Foot\n";
  const CommandRun joint =
      retarget(bandai_walk(), reactidle_clip(), out, " --target-map " + quoted(dir / "wrong.map"));
  EXPECT_EQ(joint.exit_code, 1) << joint.output;
  EXPECT_NE(joint.output.find("no joint named 'Foot'"), std::string::npos) << joint.output;

  // A skeleton whose joints say nothing: the first required role is named.
  std::ofstream(dir / "blob.bvh") << "HIERARCHY\nROOT A\n{\n  OFFSET 0 0 0\n  CHANNELS 3 "
                                     "Xposition Yposition Zposition\n  End Site\n  {\n    OFFSET "
                                     "0 1 0\n  }\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0\n";
  const CommandRun roles = retarget(dir / "blob.bvh", reactidle_clip(), out);
  EXPECT_EQ(roles.exit_code, 1) << roles.output;
  EXPECT_NE(roles.output.find("hips"), std::string::npos) << roles.output;

  const CommandRun extension = retarget(dir / "bad.map", reactidle_clip(), out);
  EXPECT_EQ(extension.exit_code, 2) << extension.output;
  EXPECT_NE(extension.output.find(quoted(dir / "bad.map")), std::string::npos) << extension.output;
  const CommandRun missing = retarget(dir / "none.bvh", reactidle_clip(), out);
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_NE(missing.output.find("none.bvh"), std::string::npos) << missing.output;
  EXPECT_FALSE(fs::exists(out));
}

TEST(RetargetCli, BuildTargetPutsTheDatabaseOnThatSkeletonAndRetargetReadsIt) {
  const fs::path dir = test::scratch_dir();
  const fs::path db_path = dir / "db.mmdb";
  const CommandRun build =
      run_mm("build " + quoted(bandai_walk()) + " " +
             quoted(test::clip_path("dataset-2_walk-turn-left_normal_001")) + " --target " +
             quoted(reactidle_clip()) + " -o " + quoted(db_path));
  ASSERT_EQ(build.exit_code, 0) << build.output;
  EXPECT_NE(build.output.find("2 clip(s) retargeted"), std::string::npos) << build.output;
  Result<Database> db = load_database(db_path);
  ASSERT_TRUE(db) << db.message();
  const Skeleton target = in_metres(reactidle_clip()).skeleton;
  ASSERT_EQ(db->joint_count(), target.joint_count() + 1);
  for (int j = 0; j < target.joint_count(); ++j) {
    EXPECT_EQ(db->skeleton().name(j + 1), target.name(j));
    EXPECT_EQ(db->skeleton().parent(j + 1), target.parent(j) + 1) << target.name(j);
    EXPECT_EQ(db->skeleton().rest(j + 1).translation, target.rest(j).translation) << target.name(j);
  }
  EXPECT_EQ(db->skeleton().name(db->roles().left_foot), "foot.L");

  // The database as a target: its skeleton without the simulation root, in metres.
  const fs::path out = dir / "walk_on_db.bvh";
  const CommandRun run = retarget(bandai_walk(), db_path, out);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  expect_same_skeleton(in_file_units(out).skeleton, target, 1e-6f);
}

}  // namespace
}  // namespace mm
