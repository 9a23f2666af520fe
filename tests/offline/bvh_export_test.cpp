// Tests of the BVH exporter: the text it writes (hierarchy, offsets in the requested units,
// channels, End Sites, frame lines), round trips through the importer (real Bandai and
// ReActIdle clips, rotations at and near gimbal lock, a skeleton that is not depth-first), and
// the refusals of save_bvh.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "mm/database/files.hpp"
#include "mm/offline/bvh.hpp"
#include "mm/runtime/pose.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

constexpr float kPositionTolerance = 1e-5f;  // metres
constexpr float kRotationTolerance = 1e-5f;  // per quaternion component, up to sign

glm::quat zxy_rotation(float z_degrees, float x_degrees, float y_degrees) {
  return glm::angleAxis(glm::radians(z_degrees), glm::vec3(0, 0, 1)) *
         glm::angleAxis(glm::radians(x_degrees), glm::vec3(1, 0, 0)) *
         glm::angleAxis(glm::radians(y_degrees), glm::vec3(0, 1, 0));
}

// A clip built by hand: `names` with `parents`, rest translations `rest`, and one pose per
// entry of `frames` (each joint_count local transforms).
Clip make_clip(std::vector<std::string> names, std::vector<int> parents,
               const std::vector<glm::vec3>& rest,
               const std::vector<std::vector<Transform>>& frames) {
  std::vector<Transform> rest_transforms;
  for (const glm::vec3& offset : rest) rest_transforms.push_back({{1, 0, 0, 0}, offset, {1, 1, 1}});
  Result<Skeleton> skeleton =
      Skeleton::create(std::move(names), std::move(parents), std::move(rest_transforms));
  EXPECT_TRUE(skeleton) << skeleton.message();
  Clip clip;
  clip.name = "made";
  clip.skeleton = std::move(skeleton).value();
  clip.frame_time = 0.04f;
  clip.frame_count = static_cast<int>(frames.size());
  for (const std::vector<Transform>& pose : frames) {
    clip.local.insert(clip.local.end(), pose.begin(), pose.end());
  }
  return clip;
}

// Hips -> Spine -> Head, and a second root Prop; Head and Prop are leaves.
Clip three_joints_and_a_prop() {
  const std::vector<glm::vec3> rest = {
      {0.0f, 0.5f, 0.0f}, {0.0f, 0.25f, 0.0f}, {0.0f, 0.125f, 0.0f}, {1.5f, 0.0f, -0.5f}};
  std::vector<Transform> pose(4);
  for (size_t j = 0; j < 4; ++j) pose[j].translation = rest[j];
  std::vector<Transform> moved = pose;
  moved[0].translation = {0.25f, 0.75f, -1.0f};
  moved[1].rotation = zxy_rotation(10.0f, 20.0f, 30.0f);
  moved[3].translation = {2.0f, 0.5f, 0.0f};  // leaves its offset: needs the position channels
  Clip clip = make_clip({"Hips", "Spine", "Head", "Prop"}, {-1, 0, 1, -1}, rest, {pose, moved});
  clip.end_sites = {{0, 0, 0}, {0, 0, 0}, {0.0f, 0.0625f, 0.0f}, {0, 0, 0}};
  return clip;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

bool has_line(const std::vector<std::string>& lines, const std::string& wanted) {
  return std::find(lines.begin(), lines.end(), wanted) != lines.end();
}

float quaternion_distance(const glm::quat& a, const glm::quat& b) {
  float same = 0.0f, opposite = 0.0f;
  for (int i = 0; i < 4; ++i) {
    same = std::max(same, std::abs(a[i] - b[i]));
    opposite = std::max(opposite, std::abs(a[i] + b[i]));
  }
  return std::min(same, opposite);
}

// Parses `text` with units of 1 / units_per_metre and checks that it gives back `original`:
// names, parents, offsets, End Sites, frame count and time, and per frame the local rotations
// (up to sign), local translations and global positions. Joints are matched by name, so a
// skeleton the exporter had to reorder is compared joint for joint.
void expect_round_trip(const Clip& original, const std::string& text, float units_per_metre) {
  Result<Clip> back = parse_bvh(text, "exported.bvh", BvhOptions{1.0f / units_per_metre});
  ASSERT_TRUE(back) << back.message();
  ASSERT_EQ(back->joint_count(), original.joint_count());
  EXPECT_EQ(back->frame_count, original.frame_count);
  EXPECT_EQ(back->frame_time, original.frame_time);
  const int joints = original.joint_count();
  std::vector<int> in_back(static_cast<size_t>(joints));
  for (int j = 0; j < joints; ++j) {
    in_back[static_cast<size_t>(j)] = back->skeleton.find(original.skeleton.name(j));
    ASSERT_GE(in_back[static_cast<size_t>(j)], 0) << original.skeleton.name(j);
    const int b = in_back[static_cast<size_t>(j)];
    const int parent = original.skeleton.parent(j);
    EXPECT_EQ(back->skeleton.parent(b),
              parent < 0 ? -1 : back->skeleton.find(original.skeleton.name(parent)));
    EXPECT_LT(
        glm::length(back->skeleton.rest(b).translation - original.skeleton.rest(j).translation),
        kPositionTolerance);
    const glm::vec3 end_site =
        original.end_sites.empty() ? glm::vec3(0.0f) : original.end_sites[static_cast<size_t>(j)];
    ASSERT_EQ(back->end_sites.size(), static_cast<size_t>(joints));
    EXPECT_LT(glm::length(back->end_sites[static_cast<size_t>(b)] - end_site), kPositionTolerance)
        << original.skeleton.name(j);
  }
  std::vector<Transform> global(static_cast<size_t>(joints));
  std::vector<Transform> global_back(static_cast<size_t>(joints));
  const int frames = std::min(original.frame_count, back->frame_count);
  float worst_rotation = 0.0f, worst_translation = 0.0f, worst_position = 0.0f;
  for (int f = 0; f < frames; ++f) {
    forward_kinematics(original.skeleton.parents(), original.pose(f), global);
    forward_kinematics(back->skeleton.parents(), back->pose(f), global_back);
    for (int j = 0; j < joints; ++j) {
      const size_t a = static_cast<size_t>(j);
      const size_t b = static_cast<size_t>(in_back[a]);
      worst_rotation = std::max(worst_rotation, quaternion_distance(original.pose(f)[a].rotation,
                                                                    back->pose(f)[b].rotation));
      worst_translation = std::max(worst_translation, glm::length(original.pose(f)[a].translation -
                                                                  back->pose(f)[b].translation));
      worst_position =
          std::max(worst_position, glm::length(global[a].translation - global_back[b].translation));
    }
  }
  EXPECT_LT(worst_rotation, kRotationTolerance);
  EXPECT_LT(worst_translation, kPositionTolerance);
  EXPECT_LT(worst_position, kPositionTolerance);
}

// ---------------------------------------------------------------------------------------------
// The text.

TEST(BvhExport, HierarchyListsJointsWithOffsetsInTheRequestedUnits) {
  const std::vector<std::string> lines = lines_of(format_bvh(three_joints_and_a_prop(), 100.0f));
  ASSERT_GE(lines.size(), 5u);
  EXPECT_EQ(lines[0], "HIERARCHY");
  EXPECT_EQ(lines[1], "ROOT Hips");
  EXPECT_EQ(lines[2], "{");
  EXPECT_EQ(lines[3], "\tOFFSET 0 50 0");
  EXPECT_EQ(lines[4], "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation");
  EXPECT_TRUE(has_line(lines, "\tJOINT Spine"));
  EXPECT_TRUE(has_line(lines, "\t\tOFFSET 0 25 0"));
  EXPECT_TRUE(has_line(lines, "\t\tJOINT Head"));
  EXPECT_TRUE(has_line(lines, "\t\t\tOFFSET 0 12.5 0"));
  // The second root, and the End Sites: Head's from end_sites, Prop's zero.
  EXPECT_TRUE(has_line(lines, "ROOT Prop"));
  EXPECT_TRUE(has_line(lines, "\tOFFSET 150 0 -50"));
  EXPECT_TRUE(has_line(lines, "\t\t\t\tOFFSET 0 6.25 0"));
  EXPECT_TRUE(has_line(lines, "\t\tOFFSET 0 0 0"));
  EXPECT_EQ(std::count(lines.begin(), lines.end(), "\t\t\tEnd Site"), 1);  // Head's
  EXPECT_EQ(std::count(lines.begin(), lines.end(), "\tEnd Site"), 1);      // Prop's
  const auto channel_lines = std::count_if(lines.begin(), lines.end(), [](const std::string& l) {
    return l.find("CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation") !=
           std::string::npos;
  });
  EXPECT_EQ(channel_lines, 4);

  // Metres: the same offsets, unscaled.
  const std::vector<std::string> metres = lines_of(format_bvh(three_joints_and_a_prop(), 1.0f));
  EXPECT_TRUE(has_line(metres, "\tOFFSET 0 0.5 0"));
  EXPECT_TRUE(has_line(metres, "\tOFFSET 1.5 0 -0.5"));
}

TEST(BvhExport, MotionHasTheFrameCountTimeAndOneLinePerFrame) {
  const Clip clip = three_joints_and_a_prop();
  const std::vector<std::string> lines = lines_of(format_bvh(clip, 100.0f));
  const auto motion = std::find(lines.begin(), lines.end(), "MOTION");
  ASSERT_NE(motion, lines.end());
  ASSERT_EQ(lines.end() - motion, 5);  // MOTION, Frames, Frame Time, two frames
  EXPECT_EQ(motion[1], "Frames: 2");
  EXPECT_EQ(motion[2], "Frame Time: 0.04");
  // Rest frame: every rotation zero, translations the offsets in centimetres, in file order.
  EXPECT_EQ(motion[3], "0 50 0 0 0 0 0 25 0 0 0 0 0 12.5 0 0 0 0 150 0 -50 0 0 0");
  std::istringstream second(motion[4]);
  std::vector<float> values;
  for (float v; second >> v;) values.push_back(v);
  ASSERT_EQ(values.size(), 24u);
  EXPECT_EQ(values[0], 25.0f);
  EXPECT_EQ(values[1], 75.0f);
  EXPECT_EQ(values[2], -100.0f);
  // Spine's Zrotation Xrotation Yrotation, as built.
  EXPECT_NEAR(values[9], 10.0f, 1e-4f);
  EXPECT_NEAR(values[10], 20.0f, 1e-4f);
  EXPECT_NEAR(values[11], 30.0f, 1e-4f);
  EXPECT_EQ(values[18], 200.0f);  // Prop's moved translation, not its offset
}

TEST(BvhExport, FrameTimeKeepsEveryDigitOfTheFloat) {
  Clip clip = three_joints_and_a_prop();
  clip.frame_time = 1.0f / 120.0f;
  Result<Clip> back = parse_bvh(format_bvh(clip, 100.0f), "t.bvh");
  ASSERT_TRUE(back) << back.message();
  EXPECT_EQ(back->frame_time, clip.frame_time);
}

// ---------------------------------------------------------------------------------------------
// Round trips.

TEST(BvhExport, SmallClipRoundTripsInCentimetresAndMetres) {
  const Clip clip = three_joints_and_a_prop();
  for (const float units : {100.0f, 1.0f, 39.3700787f}) {
    SCOPED_TRACE(units);
    expect_round_trip(clip, format_bvh(clip, units), units);
  }
}

TEST(BvhExport, RotationsAtAndNearGimbalLockRoundTripWithoutNan) {
  // X at exactly and nearly +-90 degrees, where Z and Y share one degree of freedom, combined
  // with Z and Y angles of every sign; then random rotations for good measure.
  std::vector<glm::quat> rotations;
  for (const float x : {90.0f, -90.0f, 89.999f, -89.999f, 90.001f, -90.001f, 89.9f, 270.0f}) {
    for (const float z : {0.0f, 35.0f, -120.0f, 180.0f}) {
      for (const float y : {0.0f, 60.0f, -170.0f}) rotations.push_back(zxy_rotation(z, x, y));
    }
  }
  rotations.push_back(glm::angleAxis(glm::radians(90.0f), glm::vec3(1, 0, 0)));
  rotations.push_back(glm::angleAxis(glm::radians(-90.0f), glm::vec3(1, 0, 0)));
  rotations.push_back(glm::angleAxis(glm::radians(180.0f), glm::vec3(0, 1, 0)));
  std::mt19937 random(7);
  std::normal_distribution<float> normal;
  for (int i = 0; i < 200; ++i) {
    rotations.push_back(
        glm::normalize(glm::quat(normal(random), normal(random), normal(random), normal(random))));
  }
  // A chain of four joints, one metre apart, each frame turning every joint by the next
  // rotations: errors in the angles show up in the leaf's position, three metres out.
  const std::vector<glm::vec3> rest = {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}, {0, 1, 0}};
  std::vector<std::vector<Transform>> frames;
  for (size_t r = 0; r < rotations.size(); ++r) {
    std::vector<Transform> pose(4);
    for (size_t j = 0; j < 4; ++j) {
      pose[j].translation = rest[j];
      pose[j].rotation = rotations[(r + j * 37) % rotations.size()];
    }
    frames.push_back(pose);
  }
  const Clip clip = make_clip({"A", "B", "C", "D"}, {-1, 0, 1, 2}, rest, frames);
  ASSERT_TRUE(clip.validate()) << clip.validate().message();
  const std::string text = format_bvh(clip, 100.0f);
  EXPECT_EQ(text.find("nan"), std::string::npos);
  EXPECT_EQ(text.find("inf"), std::string::npos);
  expect_round_trip(clip, text, 100.0f);
}

TEST(BvhExport, SkeletonThatIsNotDepthFirstIsWrittenDepthFirst) {
  // Joint 3 is a child of joint 1 but listed after joint 2: BVH nesting lists it right after
  // its parent, and its frame values must follow it there.
  const std::vector<glm::vec3> rest = {{0, 1, 0}, {0.5f, 0, 0}, {-0.5f, 0, 0}, {0, 0.25f, 0}};
  std::vector<Transform> pose(4);
  for (size_t j = 0; j < 4; ++j) {
    pose[j].translation = rest[j];
    pose[j].rotation = zxy_rotation(10.0f * static_cast<float>(j), 5.0f, -20.0f);
  }
  const Clip clip = make_clip({"Root", "Left", "Right", "LeftTip"}, {-1, 0, 0, 1}, rest, {pose});
  const std::string text = format_bvh(clip, 100.0f);
  Result<Clip> back = parse_bvh(text, "reordered.bvh");
  ASSERT_TRUE(back) << back.message();
  EXPECT_EQ(back->skeleton.names(), (std::vector<std::string>{"Root", "Left", "LeftTip", "Right"}));
  expect_round_trip(clip, text, 100.0f);
}

TEST(BvhExport, RealBandaiClipsRoundTrip) {
  for (const char* stem :
       {"dataset-2_walk_normal_001", "dataset-1_dash_normal_001", "dataset-1_walk-back_normal_001",
        "dataset-2_raise-up-both-hands_normal_001"}) {
    SCOPED_TRACE(stem);
    Result<Clip> clip = load_bvh(test::clip_path(stem));
    ASSERT_TRUE(clip) << clip.message();
    expect_round_trip(*clip, format_bvh(*clip, 100.0f), 100.0f);
  }
}

TEST(BvhExport, ReActIdleClipWithMixedRotationOrdersRoundTrips) {
  // Read in metres (automatic units) from channels in XYZ, YXZ and other orders, and some
  // joints without position channels; written with ZXY everywhere.
  Result<Clip> clip =
      load_bvh(test::mocap_dir() / "reactidle" / "genuine" / "000_genuine.bvh", BvhOptions{0.0f});
  ASSERT_TRUE(clip) << clip.message();
  for (const float units : {1.0f, 100.0f}) {
    SCOPED_TRACE(units);
    expect_round_trip(*clip, format_bvh(*clip, units), units);
  }
}

TEST(BvhExport, SaveWritesWhatFormatReturnsAndLoadReadsItBack) {
  const Clip clip = three_joints_and_a_prop();
  const std::filesystem::path path = test::scratch_dir() / "saved.bvh";
  ASSERT_TRUE(save_bvh(clip, path));
  auto contents = read_whole_file(path);
  ASSERT_TRUE(contents) << contents.message();
  EXPECT_EQ(contents->text(), format_bvh(clip, 100.0f));
  Result<Clip> back = load_bvh(path);  // the importer's default: centimetres
  ASSERT_TRUE(back) << back.message();
  EXPECT_EQ(back->name, "saved");
  expect_round_trip(clip, std::string(contents->text()), 100.0f);
}

// ---------------------------------------------------------------------------------------------
// Refusals.

void expect_refused(const Status& status, const std::filesystem::path& path,
                    const std::vector<std::string>& words) {
  ASSERT_FALSE(status.ok()) << "accepted";
  const std::string& message = status.message();
  EXPECT_EQ(message.rfind(path.string() + ": ", 0), 0u) << message;
  for (const std::string& word : words) {
    EXPECT_NE(message.find(word), std::string::npos) << "wanted '" << word << "' in: " << message;
  }
}

TEST(BvhExportRefused, AnInvalidClipWithItsValidationMessage) {
  const std::filesystem::path path = test::scratch_dir() / "invalid.bvh";
  Clip clip = three_joints_and_a_prop();
  clip.local.pop_back();
  const std::string validation = clip.validate().message();
  ASSERT_FALSE(validation.empty());
  expect_refused(save_bvh(clip, path), path, {validation});

  clip = three_joints_and_a_prop();
  clip.local[5].rotation = glm::quat(2.0f, 0.0f, 0.0f, 0.0f);  // not unit
  expect_refused(save_bvh(clip, path), path, {clip.validate().message()});
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(BvhExportRefused, UnitsThatAreNotFiniteAndPositive) {
  const std::filesystem::path path = test::scratch_dir() / "units.bvh";
  for (const float units : {0.0f, -100.0f, std::numeric_limits<float>::infinity(),
                            std::numeric_limits<float>::quiet_NaN()}) {
    SCOPED_TRACE(units);
    expect_refused(save_bvh(three_joints_and_a_prop(), path, units), path,
                   {"expected units_per_metre to be finite and > 0"});
  }
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(BvhExportRefused, ValuesThatOverflowInFileUnits) {
  const std::filesystem::path path = test::scratch_dir() / "huge.bvh";
  Clip clip = three_joints_and_a_prop();
  clip.local[4].translation.x = 1e36f;  // frame 1, Hips: finite in metres, not in millimetres
  ASSERT_TRUE(clip.validate());
  expect_refused(save_bvh(clip, path, 1000.0f), path, {"frame 1", "'Hips'", "not finite"});
  ASSERT_TRUE(save_bvh(clip, path, 1.0f));
}

TEST(BvhExportRefused, JointNamesThatAreNotOneToken) {
  const std::filesystem::path path = test::scratch_dir() / "names.bvh";
  for (const char* name : {"Left Arm", "Tab\tbed", "{"}) {
    SCOPED_TRACE(name);
    const std::vector<glm::vec3> rest = {{0, 1, 0}, {0, 1, 0}};
    const Clip clip = make_clip({"Root", name}, {-1, 0}, rest, {std::vector<Transform>(2)});
    expect_refused(save_bvh(clip, path), path, {"joint '" + std::string(name) + "'", "BVH"});
  }
}

TEST(BvhExportRefused, AFileThatCannotBeWrittenIsNamedWithTheReason) {
  const std::filesystem::path missing = test::scratch_dir() / "no_such_folder" / "out.bvh";
  expect_refused(save_bvh(three_joints_and_a_prop(), missing), missing,
                 {"cannot write the BVH file", "No such file or directory"});

  const std::filesystem::path folder = test::scratch_dir();
  expect_refused(save_bvh(three_joints_and_a_prop(), folder), folder,
                 {"cannot write the BVH file", "it is a folder"});
}

}  // namespace
}  // namespace mm
