// Tests of the BVH importer: every malformed input is refused with file, line and what was
// expected; channel orders and conventions checked against hand-built GLM matrices; stress
// inputs (deep hierarchy, huge declared frame count); and the real clips.

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtx/quaternion.hpp>

#include "mm/database/files.hpp"
#include "mm/offline/bvh.hpp"
#include "mm/runtime/pose.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

constexpr const char* kFixturePath = "fixtures/two_joints.bvh";

// Line numbers of this fixture are used by the malformed-input tests below.
//  1 HIERARCHY          6 JOINT Spine      11 {                16 MOTION
//  2 ROOT Hips          7 {                12 OFFSET 0 5 0     17 Frames: 2
//  3 {                  8 OFFSET 0 10 0    13 }                18 Frame Time: ...
//  4 OFFSET 0 90 0      9 CHANNELS 3 ...   14 }                19 frame 1
//  5 CHANNELS 6 ...    10 End Site         15 }                20 frame 2
std::vector<std::string> fixture_lines() {
  return {
      "HIERARCHY",
      "ROOT Hips",
      "{",
      "\tOFFSET 0 90 0",
      "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
      "\tJOINT Spine",
      "\t{",
      "\t\tOFFSET 0 10 0",
      "\t\tCHANNELS 3 Zrotation Xrotation Yrotation",
      "\t\tEnd Site",
      "\t\t{",
      "\t\t\tOFFSET 0 5 0",
      "\t\t}",
      "\t}",
      "}",
      "MOTION",
      "Frames: 2",
      "Frame Time: 0.0333333",
      "0 90 0 0 0 0 0 0 0",
      "1 91 2 10 20 30 40 50 60",
  };
}

std::string join(const std::vector<std::string>& lines, const std::string& end = "\n") {
  std::string text;
  for (const std::string& line : lines) text += line + end;
  return text;
}

// The fixture with line `number` (1-based) replaced by `replacement` (which may hold several
// lines or be empty to delete it).
std::string fixture_with_line(int number, const std::string& replacement) {
  std::vector<std::string> lines = fixture_lines();
  std::string text;
  for (int i = 0; i < static_cast<int>(lines.size()); ++i) {
    if (i + 1 == number) {
      if (!replacement.empty()) text += replacement + "\n";
    } else {
      text += lines[i] + "\n";
    }
  }
  return text;
}

// Asserts that parsing fails with a message naming the file and the line, and containing
// every one of `words` (what was expected, what was found).
void expect_refused(const std::string& text, int line, const std::vector<std::string>& words,
                    const char* path = kFixturePath) {
  Result<Clip> clip = parse_bvh(text, path);
  ASSERT_FALSE(clip.ok()) << "accepted:\n" << text.substr(0, 2000);
  const std::string& message = clip.message();
  EXPECT_NE(message.find(std::string(path) + ":" + std::to_string(line) + ":"), std::string::npos)
      << "wanted file and line " << line << " in: " << message;
  for (const std::string& word : words) {
    EXPECT_NE(message.find(word), std::string::npos) << "wanted '" << word << "' in: " << message;
  }
}

// The number of the line on which a text ends (1 + the newlines in it).
int last_line_number(const std::string& text) {
  return 1 + static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

// The file's text, or "" when it cannot be read (the assertions on the text then fail).
std::string read_file(const std::filesystem::path& path) {
  auto contents = read_whole_file(path);
  return contents ? std::string(contents->text()) : std::string();
}

void write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// A rotation matrix from Euler angles in degrees applied in the listed order (column
// vectors: "ZXY" is Rz * Rx * Ry), built with glm::rotate, independent of the importer.
glm::mat4 euler_matrix(const std::string& order, const std::vector<float>& degrees) {
  glm::mat4 m(1.0f);
  for (size_t k = 0; k < order.size(); ++k) {
    glm::vec3 axis(0.0f);
    axis[order[k] - 'X'] = 1.0f;
    m = glm::rotate(m, glm::radians(degrees[k]), axis);
  }
  return m;
}

void expect_near_matrix(const glm::mat3& actual, const glm::mat3& expected, float tolerance) {
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) {
      EXPECT_NEAR(actual[c][r], expected[c][r], tolerance) << "column " << c << " row " << r;
    }
  }
}

void expect_near_vec(const glm::vec3& actual, const glm::vec3& expected, float tolerance) {
  EXPECT_NEAR(actual.x, expected.x, tolerance);
  EXPECT_NEAR(actual.y, expected.y, tolerance);
  EXPECT_NEAR(actual.z, expected.z, tolerance);
}

std::vector<Transform> global_pose(const Clip& clip, int frame) {
  std::vector<Transform> global(static_cast<size_t>(clip.joint_count()));
  forward_kinematics(clip.skeleton.parents(), clip.pose(frame), global);
  return global;
}

// ---------------------------------------------------------------------------------------------
// The fixture itself, and the conventions.

TEST(BvhParse, FixtureJointsOffsetsAndFrames) {
  Result<Clip> clip = parse_bvh(join(fixture_lines()), kFixturePath);
  ASSERT_TRUE(clip.ok()) << clip.message();
  EXPECT_EQ(clip->name, "two_joints");
  EXPECT_EQ(clip->source_path, kFixturePath);
  // The End Site is not a joint.
  ASSERT_EQ(clip->joint_count(), 2);
  EXPECT_EQ(clip->skeleton.names(), (std::vector<std::string>{"Hips", "Spine"}));
  EXPECT_EQ(clip->skeleton.parents(), (std::vector<int>{-1, 0}));
  EXPECT_EQ(clip->frame_count, 2);
  EXPECT_NEAR(clip->frame_time, 0.0333333f, 1e-7f);
  EXPECT_EQ(clip->local.size(), 4u);
  EXPECT_TRUE(clip->validate().ok()) << clip->validate().message();
  EXPECT_TRUE(clip->warnings.empty());
  // Rest: OFFSET in metres, identity rotation.
  expect_near_vec(clip->skeleton.rest(0).translation, {0.0f, 0.9f, 0.0f}, 1e-6f);
  expect_near_vec(clip->skeleton.rest(1).translation, {0.0f, 0.1f, 0.0f}, 1e-6f);
  EXPECT_EQ(clip->skeleton.rest(1).rotation, glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
  // Frame 2: position channels replace the root's offset; Spine has none, so keeps its offset.
  expect_near_vec(clip->pose(1)[0].translation, {0.01f, 0.91f, 0.02f}, 1e-6f);
  expect_near_vec(clip->pose(1)[1].translation, {0.0f, 0.1f, 0.0f}, 1e-6f);
  expect_near_matrix(glm::mat3_cast(clip->pose(1)[0].rotation),
                     glm::mat3(euler_matrix("ZXY", {10.0f, 20.0f, 30.0f})), 1e-5f);
  expect_near_matrix(glm::mat3_cast(clip->pose(1)[1].rotation),
                     glm::mat3(euler_matrix("ZXY", {40.0f, 50.0f, 60.0f})), 1e-5f);
}

TEST(BvhParse, ScaleOptionConvertsUnits) {
  Result<Clip> clip = parse_bvh(join(fixture_lines()), kFixturePath, BvhOptions{1.0f});
  ASSERT_TRUE(clip.ok()) << clip.message();
  expect_near_vec(clip->skeleton.rest(0).translation, {0.0f, 90.0f, 0.0f}, 1e-5f);
  expect_near_vec(clip->pose(1)[0].translation, {1.0f, 91.0f, 2.0f}, 1e-5f);
}

TEST(BvhParse, RefusesInvalidScaleOption) {
  for (const float scale : {-1.0f, std::numeric_limits<float>::infinity()}) {
    Result<Clip> clip = parse_bvh(join(fixture_lines()), kFixturePath, BvhOptions{scale});
    ASSERT_FALSE(clip.ok());
    EXPECT_NE(clip.message().find(kFixturePath), std::string::npos);
    EXPECT_NE(clip.message().find("expected BvhOptions::scale"), std::string::npos);
  }
}

TEST(BvhUnits, PickedFromTheSkeletonsSize) {
  EXPECT_EQ(bvh_units_to_metres(0.9f), 1.0f);
  EXPECT_EQ(bvh_units_to_metres(36.0f), 0.0254f);
  EXPECT_EQ(bvh_units_to_metres(95.0f), 0.01f);
  EXPECT_EQ(bvh_units_to_metres(950.0f), 0.001f);
}

TEST(BvhUnits, RealFilesInCentimetresAndMetresComeOutInMetres) {
  // Bandai (centimetres) and ReActIdle (metres): with automatic units both legs measure
  // 0.6-0.9 m, and the End Sites are kept in metres.
  const std::filesystem::path files[] = {
      test::clip_path("dataset-2_walk_normal_001"),
      test::mocap_dir() / "reactidle" / "genuine" / "000_genuine.bvh"};
  for (const std::filesystem::path& file : files) {
    Result<Clip> clip = load_bvh(file, BvhOptions{0.0f});
    ASSERT_TRUE(clip) << clip.message();
    const Skeleton& sk = clip->skeleton;
    const int foot = sk.find("Foot_L") >= 0 ? sk.find("Foot_L") : sk.find("foot.L");
    ASSERT_GE(foot, 0) << file;
    const float leg =
        glm::length(sk.rest(foot).translation) + glm::length(sk.rest(sk.parent(foot)).translation);
    EXPECT_GT(leg, 0.6f) << file;
    EXPECT_LT(leg, 0.9f) << file;
    ASSERT_EQ(clip->end_sites.size(), static_cast<size_t>(sk.joint_count()));
    EXPECT_LT(glm::length(clip->end_sites[static_cast<size_t>(foot)]), 0.3f) << file;
  }
}

// Global positions of a three-joint chain, each joint with a different rotation order, against
// a chain of glm matrices computed by hand.
TEST(BvhParse, ForwardKinematicsMatchesHandBuiltMatrices) {
  const std::string text =
      "HIERARCHY\n"
      "ROOT A\n{\n"
      "  OFFSET 1 2 3\n"
      "  CHANNELS 6 Xposition Yposition Zposition Xrotation Yrotation Zrotation\n"
      "  JOINT B\n  {\n"
      "    OFFSET 10 0 0\n"
      "    CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "    JOINT C\n    {\n"
      "      OFFSET 0 20 5\n"
      "      CHANNELS 3 Yrotation Zrotation Xrotation\n"
      "      End Site\n      {\n        OFFSET 0 0 7\n      }\n"
      "    }\n"
      "  }\n"
      "}\n"
      "MOTION\nFrames: 1\nFrame Time: 0.04\n"
      "5 6 7 30 -45 60 20 70 -10 15 25 35\n";
  Result<Clip> clip = parse_bvh(text, "chain.bvh");
  ASSERT_TRUE(clip.ok()) << clip.message();
  ASSERT_EQ(clip->joint_count(), 3);

  // By hand, in metres: A = T(5,6,7) Rx Ry Rz, B = A T(10,0,0) Rz Rx Ry, C = B T(0,20,5) Ry Rz Rx.
  const glm::mat4 a = glm::translate(glm::mat4(1.0f), glm::vec3(0.05f, 0.06f, 0.07f)) *
                      euler_matrix("XYZ", {30.0f, -45.0f, 60.0f});
  const glm::mat4 b = a * glm::translate(glm::mat4(1.0f), glm::vec3(0.10f, 0.0f, 0.0f)) *
                      euler_matrix("ZXY", {20.0f, 70.0f, -10.0f});
  const glm::mat4 c = b * glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.20f, 0.05f)) *
                      euler_matrix("YZX", {15.0f, 25.0f, 35.0f});

  const std::vector<Transform> global = global_pose(*clip, 0);
  expect_near_vec(global[0].translation, glm::vec3(a[3]), 1e-6f);
  expect_near_vec(global[1].translation, glm::vec3(b[3]), 1e-6f);
  expect_near_vec(global[2].translation, glm::vec3(c[3]), 1e-6f);
  expect_near_matrix(glm::mat3_cast(global[2].rotation), glm::mat3(c), 1e-5f);
  // The hand computation keeps bone lengths: C sits |(0, 0.20, 0.05)| from B.
  EXPECT_NEAR(glm::length(glm::vec3(c[3]) - glm::vec3(b[3])), std::sqrt(0.04f + 0.0025f), 1e-6f);
}

TEST(BvhParse, EveryRotationOrderComposesInListedOrder) {
  const std::vector<std::string> orders = {"XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"};
  const std::vector<float> listed_values = {40.0f, -75.0f, 120.0f};
  for (const std::string& order : orders) {
    SCOPED_TRACE(order);
    std::string channels;
    for (char axis : order) channels += std::string(" ") + axis + "rotation";
    const std::string text = "HIERARCHY\nROOT R\n{\nOFFSET 0 0 0\nCHANNELS 3" + channels +
                             "\nEnd Site\n{\nOFFSET 0 1 0\n}\n}\nMOTION\nFrames: 1\n"
                             "Frame Time: 0.1\n40 -75 120\n";
    Result<Clip> clip = parse_bvh(text, "order.bvh");
    ASSERT_TRUE(clip.ok()) << clip.message();
    expect_near_matrix(glm::mat3_cast(clip->pose(0)[0].rotation),
                       glm::mat3(euler_matrix(order, listed_values)), 1e-5f);
    EXPECT_NEAR(glm::length(clip->pose(0)[0].rotation), 1.0f, 1e-6f);
  }
}

TEST(BvhParse, PositionAndRotationChannelsInAnyOrder) {
  // Position and rotation channels interleaved: rotation order is Z, X, Y as listed.
  const std::string text =
      "HIERARCHY\nROOT R\n{\nOFFSET 1 2 3\n"
      "CHANNELS 6 Zrotation Yposition Xrotation Xposition Yrotation Zposition\n"
      "End Site\n{\nOFFSET 0 1 0\n}\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n"
      "10 200 -20 100 30 300\n";
  Result<Clip> clip = parse_bvh(text, "mixed.bvh", BvhOptions{1.0f});
  ASSERT_TRUE(clip.ok()) << clip.message();
  expect_near_vec(clip->pose(0)[0].translation, {100.0f, 200.0f, 300.0f}, 1e-5f);
  expect_near_matrix(glm::mat3_cast(clip->pose(0)[0].rotation),
                     glm::mat3(euler_matrix("ZXY", {10.0f, -20.0f, 30.0f})), 1e-5f);
}

TEST(BvhParse, ThreeChannelJointsPositionOnlyPartialAndNoChannels) {
  const std::string text =
      "HIERARCHY\n"
      "ROOT R\n{\nOFFSET 1 2 3\nCHANNELS 3 Xposition Yposition Zposition\n"   // position only
      "JOINT P\n{\nOFFSET 4 5 6\nCHANNELS 1 Yposition\n"                      // one position
      "JOINT N\n{\nOFFSET 7 8 9\nCHANNELS 0\n"                                // no channels
      "JOINT Q\n{\nOFFSET 0 1 0\nCHANNELS 3 Yrotation Xrotation Zrotation\n"  // rotation only
      "End Site\n{\nOFFSET 0 1 0\n}\n}\n}\n}\n}\n"
      "MOTION\nFrames: 1\nFrame Time: 0.1\n10 20 30 50 5 15 25\n";
  Result<Clip> clip = parse_bvh(text, "channels.bvh", BvhOptions{1.0f});
  ASSERT_TRUE(clip.ok()) << clip.message();
  ASSERT_EQ(clip->joint_count(), 4);
  const auto pose = clip->pose(0);
  expect_near_vec(pose[0].translation, {10.0f, 20.0f, 30.0f}, 1e-5f);
  EXPECT_EQ(pose[0].rotation, glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
  expect_near_vec(pose[1].translation, {4.0f, 50.0f, 6.0f}, 1e-5f);  // missing axes keep OFFSET
  expect_near_vec(pose[2].translation, {7.0f, 8.0f, 9.0f}, 1e-5f);
  EXPECT_EQ(pose[2].rotation, glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
  expect_near_vec(pose[3].translation, {0.0f, 1.0f, 0.0f}, 1e-5f);
  expect_near_matrix(glm::mat3_cast(pose[3].rotation),
                     glm::mat3(euler_matrix("YXZ", {5.0f, 15.0f, 25.0f})), 1e-5f);
}

TEST(BvhParse, CrlfTabsSpacesAndBlankLinesGiveTheSameClip) {
  const std::string plain = join(fixture_lines());
  const std::string crlf = join(fixture_lines(), "\r\n");
  std::vector<std::string> spaced = fixture_lines();
  for (std::string& line : spaced) {
    std::replace(line.begin(), line.end(), '\t', ' ');
    std::string doubled;
    for (char c : line) doubled += c == ' ' ? std::string(" \t ") : std::string(1, c);
    line = doubled;
  }
  spaced.insert(spaced.begin() + 19, "");  // a blank line between the two frames
  const std::vector<std::string> variants = {
      crlf,                               // CRLF
      join(spaced),                       // mixed spaces and tabs
      join(spaced, "\r\n"),               // both
      plain.substr(0, plain.size() - 1),  // no newline at the end
      crlf.substr(0, crlf.size() - 2),    // CRLF, no final CRLF
  };
  Result<Clip> reference = parse_bvh(plain, kFixturePath);
  ASSERT_TRUE(reference.ok()) << reference.message();
  for (size_t v = 0; v < variants.size(); ++v) {
    SCOPED_TRACE("variant " + std::to_string(v));
    Result<Clip> clip = parse_bvh(variants[v], kFixturePath);
    ASSERT_TRUE(clip.ok()) << clip.message();
    EXPECT_EQ(clip->skeleton.names(), reference->skeleton.names());
    ASSERT_EQ(clip->local.size(), reference->local.size());
    for (size_t i = 0; i < clip->local.size(); ++i) {
      EXPECT_EQ(clip->local[i].translation, reference->local[i].translation);
      EXPECT_EQ(clip->local[i].rotation, reference->local[i].rotation);
    }
  }
}

TEST(BvhParse, EndSitesAreDroppedAndNamesKept) {
  const std::string text =
      "HIERARCHY\nROOT root-joint.01\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
      "JOINT Left:Arm\n{\nOFFSET 1 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
      "End Site\n{\nOFFSET 1 0 0\n}\n}\n"
      "JOINT right_arm\n{\nOFFSET -1 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
      "End Site\n{\nOFFSET -1 0 0\n}\n}\n"
      "End Site\n{\nOFFSET 0 1 0\n}\n"
      "}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0 0 0 0 0 0 0\n";
  Result<Clip> clip = parse_bvh(text, "names.bvh");
  ASSERT_TRUE(clip.ok()) << clip.message();
  EXPECT_EQ(clip->skeleton.names(),
            (std::vector<std::string>{"root-joint.01", "Left:Arm", "right_arm"}));
  EXPECT_EQ(clip->skeleton.parents(), (std::vector<int>{-1, 0, 0}));
}

// Values in many textual forms must decode exactly as std::from_chars does (the fast path
// must never round differently). With scale 1 a position channel stores the value itself.
TEST(BvhParse, NumbersDecodeExactlyLikeFromChars) {
  std::mt19937 rng(12345);
  std::vector<std::string> tokens = {
      "0", "-0", "-0.000000", ".5", "5.", "1e-3", "-2.5E+2", "3.4e38", "123456789", "0.1",
      "16777217", "9007199254740993", "1.00000005960464477539062", "0.333333333333333333333",
      "12345678901234567890123456789", "-543.347000",
      // Within a double ulp of a float midpoint: rounding to
      // double first and then to float gets these wrong.
      "72.35174942016602", "0.01362472167238593", "67.36651229858398", "62.52469825744629",
      "70.62986373901367", "0.6426003873348236", "0.07552148029208183", "0.5115454494953156"};
  for (int i = 0; i < 3000; ++i) {
    const int int_digits = static_cast<int>(rng() % 9);
    const int fraction_digits = static_cast<int>(rng() % 12);
    std::string token = rng() % 2 ? "-" : "";
    for (int d = 0; d < int_digits; ++d) token += static_cast<char>('0' + rng() % 10);
    token += ".";
    for (int d = 0; d < fraction_digits; ++d) token += static_cast<char>('0' + rng() % 10);
    if (int_digits + fraction_digits == 0) token += "0";
    tokens.push_back(token);
  }
  while (tokens.size() % 3 != 0) tokens.push_back("1");
  std::string text =
      "HIERARCHY\nROOT R\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n"
      "End Site\n{\nOFFSET 0 1 0\n}\n}\nMOTION\nFrames: " +
      std::to_string(tokens.size() / 3) + "\nFrame Time: 0.1\n";
  for (size_t i = 0; i < tokens.size(); i += 3) {
    text += tokens[i] + " " + tokens[i + 1] + " " + tokens[i + 2] + "\n";
  }
  Result<Clip> clip = parse_bvh(text, "numbers.bvh", BvhOptions{1.0f});
  ASSERT_TRUE(clip.ok()) << clip.message();
  for (size_t i = 0; i < tokens.size(); ++i) {
    float expected = 0.0f;
    const std::string& token = tokens[i];
    ASSERT_EQ(std::from_chars(token.data(), token.data() + token.size(), expected).ec, std::errc())
        << token;
    const float actual =
        clip->pose(static_cast<int>(i / 3))[0].translation[static_cast<int>(i % 3)];
    EXPECT_EQ(std::bit_cast<uint32_t>(actual), std::bit_cast<uint32_t>(expected))
        << token << ": " << actual << " vs " << expected;
  }
}

TEST(BvhParse, TinyValuesUnderflowToZeroAndLeadingPlusIsAccepted) {
  const std::string text =
      "HIERARCHY\nROOT R\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n"
      "End Site\n{\nOFFSET 0 1 0\n}\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n"
      "1e-60 +2.5 -1e-300\n";
  Result<Clip> clip = parse_bvh(text, "tiny.bvh", BvhOptions{1.0f});
  ASSERT_TRUE(clip.ok()) << clip.message();
  EXPECT_EQ(clip->pose(0)[0].translation, glm::vec3(0.0f, 2.5f, -0.0f));
}

// ---------------------------------------------------------------------------------------------
// Malformed input: each refused with the file, the line and what was expected.

TEST(BvhMalformed, EmptyFile) {
  expect_refused("", 1, {"expected 'HIERARCHY'", "end of file"});
}

TEST(BvhMalformed, TruncatedInTheHierarchy) {
  // Cut after line 9: the file ends on line 10 while joint Spine is open.
  std::string text = join(fixture_lines());
  text = text.substr(0, text.find("\t\tEnd Site"));
  expect_refused(text, 10, {"expected 'JOINT', 'End Site' or '}'", "'Spine'", "end of file"});
}

TEST(BvhMalformed, TruncatedInsideAnOffset) {
  std::string text = join(fixture_lines());
  text = text.substr(0, text.find("0 10 0") + 3);  // line 8 ends after "OFFSET 0 1"
  expect_refused(text, 8, {"expected OFFSET value 3 of 3", "'Spine'", "end of file"});
}

TEST(BvhMalformed, TruncatedInTheMotionMidLine) {
  std::string text = join(fixture_lines());
  text = text.substr(0, text.find("1 91 2 10 20") + 12);  // frame 2 cut after 5 values
  expect_refused(text, 20, {"expected 9 values", "frame 2", "found 5", "file ends"});
}

TEST(BvhMalformed, TruncatedInTheMotionBetweenLines) {
  std::string text = join(fixture_lines());
  text = text.substr(0, text.find("1 91 2"));  // ends right after frame 1's newline
  expect_refused(text, 20, {"expected 2 frames", "line 17", "found 1"});
}

TEST(BvhMalformed, TruncatedRealFilesInHierarchyAndMotion) {
  const std::filesystem::path source = test::clip_path("dataset-2_walk_normal_001");
  const std::string text = read_file(source);
  ASSERT_GT(text.size(), 10000u);
  const std::filesystem::path dir = test::scratch_dir();
  const size_t motion = text.find("MOTION");
  ASSERT_NE(motion, std::string::npos);
  // Cuts: mid-hierarchy (several places), mid-motion-line, and just after a motion line.
  size_t after_third_frame = text.find("Frame Time");
  for (int newline = 0; newline < 4; ++newline)
    after_third_frame = text.find('\n', after_third_frame) + 1;
  const std::vector<size_t> cuts = {motion / 3,      motion / 2 + 7,   motion - 5,       motion + 3,
                                    text.size() / 2, text.size() - 10, after_third_frame};
  for (size_t cut : cuts) {
    SCOPED_TRACE("cut at byte " + std::to_string(cut));
    const std::string truncated = text.substr(0, cut);
    const std::filesystem::path path = dir / ("cut_" + std::to_string(cut) + ".bvh");
    write_file(path, truncated);
    Result<Clip> clip = load_bvh(path);
    ASSERT_FALSE(clip.ok());
    const std::string where =
        path.string() + ":" + std::to_string(last_line_number(truncated)) + ":";
    EXPECT_NE(clip.message().find(where), std::string::npos)
        << "wanted " << where << " in: " << clip.message();
    EXPECT_NE(clip.message().find("expected"), std::string::npos) << clip.message();
  }
}

// Every refusal of a one-line change to the fixture: which line is replaced (the replacement
// may be empty or span two lines), the line the message must name, and what it must say.
struct LineChange {
  const char* name;
  int replaced_line;
  const char* replacement;
  int error_line;
  std::vector<std::string> words;
};

// clang-format off
const LineChange kRefusedLineChanges[] = {
    {"MotionLineWithTooFewValues", 19, "0 90 0 0 0 0 0 0", 19,
     {"expected 9 values", "frame 1", "found 8"}},
    {"MotionLineWithTooManyValues", 20, "1 91 2 10 20 30 40 50 60 70", 20,
     {"expected 9 values", "frame 2", "found more"}},
    {"FrameSpreadOverTwoLines", 19, "0 90 0 0 0\n0 0 0 0", 19, {"expected 9 values", "found 5"}},
    {"NonNumericMotionValue", 20, "1 91 2 10 abc 30 40 50 60", 20,
     {"expected a number", "value 5 of 9", "'abc'"}},
    {"NumberGluedToText", 19, "0 90 0 0 0 0 0 0 1.5x", 19, {"expected a number", "'1.5x'"}},
    {"NanMotionValue", 19, "0 90 nan 0 0 0 0 0 0", 19, {"expected a finite number", "'nan'"}},
    {"InfinityMotionValue", 20, "1 91 2 10 20 30 40 50 -inf", 20,
     {"expected a finite number", "'-inf'"}},
    {"OutOfRangeMotionValue1", 19, "0 1e999 0 0 0 0 0 0 0", 19,
     {"expected a number within float range", "'1e999'"}},
    // Finite as a double but not as a float.
    {"OutOfRangeMotionValue2", 19, "0 90 0 0 0 0 0 0 1e39", 19,
     {"expected a number within float range", "'1e39'"}},
    {"NonFiniteOffset1", 8, "\t\tOFFSET 0 inf 0", 8,
     {"expected OFFSET value 2 of 3", "finite", "'inf'"}},
    {"NonFiniteOffset2", 4, "\tOFFSET 0 1e999 0", 4, {"expected OFFSET value 2 of 3", "'1e999'"}},
    {"NonFiniteOrZeroFrameTime1", 18, "Frame Time: nan", 18, {"expected a positive frame time"}},
    {"NonFiniteOrZeroFrameTime2", 18, "Frame Time: 1e999", 18, {"expected a positive frame time"}},
    {"UnknownChannelName", 9, "\t\tCHANNELS 3 Zrotation Wrotation Yrotation", 9,
     {"expected a channel name", "'Wrotation'", "'Spine'"}},
    {"RepeatedChannelName", 9, "\t\tCHANNELS 3 Zrotation Zrotation Yrotation", 9,
     {"expected each channel at most once", "'Zrotation'"}},
    {"ChannelCountLargerThanTheNames", 9, "\t\tCHANNELS 4 Zrotation Xrotation Yrotation", 9,
     {"expected 4 channel names", "found only 3", "'End'", "line 10"}},
    {"ChannelCountSmallerThanTheNames", 9, "\t\tCHANNELS 2 Zrotation Xrotation Yrotation", 9,
     {"expected 'JOINT', 'End Site' or '}'", "'Yrotation'", "'CHANNELS 2'"}},
    {"ChannelCountOutOfRangeOrNotANumber1", 9, "\t\tCHANNELS 7 Zrotation Xrotation Yrotation", 9,
     {"expected a channel count from 0 to 6", "'7'"}},
    {"ChannelCountOutOfRangeOrNotANumber2", 9, "\t\tCHANNELS -1", 9,
     {"expected a channel count from 0 to 6", "'-1'"}},
    {"ChannelCountOutOfRangeOrNotANumber3", 9, "\t\tCHANNELS Zrotation Xrotation Yrotation", 9,
     {"expected a channel count from 0 to 6", "'Zrotation'"}},
    // Without line 15's '}', MOTION (now line 15) arrives while Hips is still open.
    {"UnbalancedBracesMissingClose", 15, "", 15,
     {"expected 'JOINT', 'End Site' or '}'", "'Hips'", "opened on line 2", "'MOTION'"}},
    {"UnbalancedBracesExtraClose", 15, "}\n}", 16, {"expected 'MOTION'", "unbalanced braces"}},
    {"MissingOpeningBrace", 7, "", 7, {"expected '{'", "'Spine'", "'OFFSET'"}},
    {"EndSiteWithAJointInside", 13, "\t\t\tJOINT Inner", 13,
     {"expected '}'", "End Site of joint 'Spine'", "'JOINT'"}},
    {"DuplicateJointNames", 6, "\tJOINT Hips", 6,
     {"expected unique joint names", "'Hips'", "first on line 2"}},
    {"MissingJointName", 6, "\tJOINT", 7, {"expected a joint name", "'{'"}},
    {"FrameCountLargerThanTheData", 17, "Frames: 3", 21, {"expected 3 frames", "found 2"}},
    {"ZeroFrameTime", 18, "Frame Time: 0", 18, {"expected a positive frame time", "'0'"}},
    {"NegativeFrameTime", 18, "Frame Time: -0.0333", 18,
     {"expected a positive frame time", "'-0.0333'"}},
    {"ZeroFrameCount", 17, "Frames: 0", 17, {"expected a positive frame count", "'0'"}},
    {"NegativeFrameCount", 17, "Frames: -5", 17, {"expected a positive frame count", "'-5'"}},
    {"NonIntegerOrHugeFrameCount1", 17, "Frames: 2.5", 17, {"expected a whole number of frames"}},
    {"NonIntegerOrHugeFrameCount2", 17, "Frames: 2147483648", 17,
     {"expected at most 2147483647 frames"}},
    {"NonIntegerOrHugeFrameCount3", 17, "Frames: 99999999999999999999999", 17,
     {"expected at most 2147483647 frames"}},
    {"MissingFrameTimeLine", 18, "", 18, {"expected 'Frame'", "'0'"}},
    {"TextAfterFrameTime", 18, "Frame Time: 0.03 0 90 0", 18,
     {"expected the end of the line after the frame time"}},
};
// clang-format on

class BvhMalformedLine : public testing::TestWithParam<LineChange> {};

TEST_P(BvhMalformedLine, IsRefusedWithTheLineAndWhatWasExpected) {
  const LineChange& change = GetParam();
  expect_refused(fixture_with_line(change.replaced_line, change.replacement), change.error_line,
                 change.words);
}

INSTANTIATE_TEST_SUITE_P(BvhMalformed, BvhMalformedLine, testing::ValuesIn(kRefusedLineChanges),
                         [](const testing::TestParamInfo<LineChange>& param) {
                           return std::string(param.param.name);
                         });

// ---------------------------------------------------------------------------------------------
// More frame lines than "Frames:" declares: the declared frames, and one warning.

// Frame 2 of the fixture (line 20), as the importer must read it.
void expect_fixture_frame_2(const Clip& clip) {
  expect_near_vec(clip.pose(1)[0].translation, {0.01f, 0.91f, 0.02f}, 1e-6f);
  expect_near_vec(clip.pose(1)[1].translation, {0.0f, 0.1f, 0.0f}, 1e-6f);
  expect_near_matrix(glm::mat3_cast(clip.pose(1)[0].rotation),
                     glm::mat3(euler_matrix("ZXY", {10.0f, 20.0f, 30.0f})), 1e-5f);
  expect_near_matrix(glm::mat3_cast(clip.pose(1)[1].rotation),
                     glm::mat3(euler_matrix("ZXY", {40.0f, 50.0f, 60.0f})), 1e-5f);
}

TEST(BvhExtraFrameLines, TheDeclaredFramesLoadWithOneWarningNamingTheFirstIgnoredLine) {
  // Lines 21 and 22 are two more well-formed frames than "Frames: 2" on line 17 declares.
  const std::string text =
      join(fixture_lines()) + "2 92 4 11 21 31 41 51 61\n3 93 6 12 22 32 42 52 62\n";
  Result<Clip> clip = parse_bvh(text, kFixturePath);
  ASSERT_TRUE(clip.ok()) << clip.message();
  EXPECT_EQ(clip->frame_count, 2);
  EXPECT_EQ(clip->local.size(), 4u);
  EXPECT_TRUE(clip->validate().ok()) << clip->validate().message();
  ASSERT_EQ(clip->warnings.size(), 1u);
  EXPECT_EQ(clip->warnings[0],
            std::string(kFixturePath) + ":21: ignored 2 frame lines beyond 'Frames: 2' on line 17");
  expect_fixture_frame_2(*clip);
}

TEST(BvhExtraFrameLines, BlankLinesAreNotCountedAndOneExtraLineIsSingular) {
  // "Frames: 1": line 20 is ignored; the blank and whitespace-only lines after it are not
  // frame lines, and the file ends without a newline.
  const std::string text = fixture_with_line(17, "Frames: 1") + "\n \t\r\n  ";
  Result<Clip> clip = parse_bvh(text, kFixturePath);
  ASSERT_TRUE(clip.ok()) << clip.message();
  EXPECT_EQ(clip->frame_count, 1);
  ASSERT_EQ(clip->warnings.size(), 1u);
  EXPECT_EQ(clip->warnings[0],
            std::string(kFixturePath) + ":20: ignored 1 frame line beyond 'Frames: 1' on line 17");
}

TEST(BvhExtraFrameLines, GarbageAfterTheDeclaredFramesIsIgnoredUnparsed) {
  // Lines 22, 23, 25 and 26 would each be refused as a frame (words, too many values, NaNs and
  // binary bytes, a brace); blank lines 21 and 24 are not counted; the last line has no newline.
  const std::string text = join(fixture_lines()) +
                           "\n"
                           "this is not a frame\r\n"
                           "1 2 3 4 5 6 7 8 9 10 11 12\n"
                           "   \n"
                           "nan nan \x01\x02\xff\n"
                           "\t}";
  Result<Clip> clip = parse_bvh(text, kFixturePath);
  ASSERT_TRUE(clip.ok()) << clip.message();
  EXPECT_EQ(clip->frame_count, 2);
  EXPECT_TRUE(clip->validate().ok()) << clip->validate().message();
  ASSERT_EQ(clip->warnings.size(), 1u);
  EXPECT_EQ(clip->warnings[0],
            std::string(kFixturePath) + ":22: ignored 4 frame lines beyond 'Frames: 2' on line 17");
  expect_fixture_frame_2(*clip);
}

TEST(BvhExtraFrameLines, FewerFrameLinesThanDeclaredAreStillRefused) {
  Result<Clip> clip = parse_bvh(fixture_with_line(17, "Frames: 3"), kFixturePath);
  ASSERT_FALSE(clip.ok());
  EXPECT_EQ(clip.message(), std::string(kFixturePath) +
                                ":21: expected 3 frames as declared by 'Frames:' on line 17, "
                                "found 2 before the end of the file");
}

TEST(BvhMalformed, NoMotionSection) {
  std::string text = join(fixture_lines());
  text = text.substr(0, text.find("MOTION"));
  expect_refused(text, 16, {"expected 'MOTION'", "end of file"});
}

TEST(BvhMalformed, NoChannelsAtAll) {
  const std::string text =
      "HIERARCHY\nROOT R\n{\nOFFSET 0 0 0\nCHANNELS 0\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n\n";
  expect_refused(text, 7, {"expected at least one channel"});
}

TEST(BvhMalformed, NotABvhFileAtAll) {
  expect_refused("\x89PNG\r\n\x1a\n\x00\x01", 1, {"expected 'HIERARCHY'", "\\x89PNG"});
}

TEST(BvhLoad, MissingFileIsNamed) {
  const std::filesystem::path path = test::scratch_dir() / "does_not_exist.bvh";
  Result<Clip> clip = load_bvh(path);
  ASSERT_FALSE(clip.ok());
  EXPECT_NE(clip.message().find(path.string()), std::string::npos) << clip.message();
  EXPECT_NE(clip.message().find("cannot open"), std::string::npos) << clip.message();
}

TEST(BvhLoad, DirectoryIsRefused) {
  const std::filesystem::path dir = test::scratch_dir();
  Result<Clip> clip = load_bvh(dir);
  ASSERT_FALSE(clip.ok());
  EXPECT_NE(clip.message().find(dir.string()), std::string::npos) << clip.message();
}

TEST(BvhLoad, LoadsWhatParseParses) {
  const std::filesystem::path path = test::scratch_dir() / "fixture.bvh";
  write_file(path, join(fixture_lines(), "\r\n"));
  Result<Clip> clip = load_bvh(path);
  ASSERT_TRUE(clip.ok()) << clip.message();
  EXPECT_EQ(clip->name, "fixture");
  EXPECT_EQ(clip->source_path, path.string());
  EXPECT_EQ(clip->frame_count, 2);
}

// ---------------------------------------------------------------------------------------------
// Stress: nothing recursive, nothing allocated from a declared size.

TEST(BvhStress, HundredThousandDeepHierarchyNeedsNoRecursion) {
  constexpr int kDepth = 100000;
  std::string text = "HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 1 Zrotation\n";
  text.reserve(static_cast<size_t>(kDepth) * 48);
  for (int i = 1; i < kDepth; ++i) {
    text += "JOINT j" + std::to_string(i) + "\n{\nOFFSET 0 1 0\nCHANNELS 1 Zrotation\n";
  }
  text += "End Site\n{\nOFFSET 0 1 0\n}\n";
  for (int i = 0; i < kDepth; ++i) text += "}\n";
  text += "MOTION\nFrames: 1\nFrame Time: 0.1\n";
  for (int i = 0; i < kDepth; ++i) text += "1 ";
  text += "\n";
  Result<Clip> clip = parse_bvh(text, "deep.bvh");
  ASSERT_TRUE(clip.ok()) << clip.message();
  ASSERT_EQ(clip->joint_count(), kDepth);
  EXPECT_EQ(clip->skeleton.parent(kDepth - 1), kDepth - 2);
  EXPECT_EQ(clip->skeleton.subtree_size(0), kDepth);
  EXPECT_EQ(clip->skeleton.name(kDepth - 1), "j99999");

  // The same depth left unclosed is refused at the end of the file, also without recursion.
  const std::string unclosed = text.substr(0, text.find("End Site"));
  expect_refused(unclosed, last_line_number(unclosed), {"expected 'JOINT', 'End Site' or '}'"},
                 "deep.bvh");
}

TEST(BvhStress, HugeDeclaredFrameCountWithLittleDataIsRefused) {
  // 2^31 - 1 frames of 2 joints would be 170 GB of transforms: refused after reading the two
  // lines that exist, with nothing allocated up front for the rest.
  expect_refused(fixture_with_line(17, "Frames: 2147483647"), 21,
                 {"expected 2147483647 frames", "found 2"});
}

TEST(BvhStress, ManyJointsWithoutChannelsCannotExpandASmallFile) {
  // 2000 joints, one channel: each 2-byte frame line would become 2000 transforms (80 kB).
  std::string text = "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 1 Xposition\n";
  for (int i = 0; i < 2000; ++i) {
    text += "JOINT j" + std::to_string(i) + "\n{\nOFFSET 0 0 0\nCHANNELS 0\n}\n";
  }
  text += "}\n";
  const int motion_line = last_line_number(text);
  text += "MOTION\nFrames: 5000\nFrame Time: 0.1\n";
  for (int i = 0; i < 5000; ++i) text += "1\n";
  expect_refused(
      text, motion_line,
      {"expected at most 16 joint transforms per byte", "2001 joints", "without channels"},
      "wide.bvh");
  // The same skeleton with a few frames is a legitimate file.
  const std::string few =
      text.substr(0, text.find("Frames:")) + "Frames: 3\nFrame Time: 0.1\n1\n2\n3\n";
  Result<Clip> clip = parse_bvh(few, "wide.bvh");
  ASSERT_TRUE(clip.ok()) << clip.message();
  EXPECT_EQ(clip->joint_count(), 2001);
  EXPECT_NEAR(clip->pose(2)[0].translation.x, 0.03f, 1e-7f);
}

TEST(BvhStress, LongGarbageTokenIsCutShortInTheMessage) {
  const std::string garbage(100000, 'x');
  Result<Clip> clip = parse_bvh(fixture_with_line(19, garbage), kFixturePath);
  ASSERT_FALSE(clip.ok());
  EXPECT_LT(clip.message().size(), 400u) << clip.message().substr(0, 400);
  EXPECT_NE(clip.message().find(std::string(kFixturePath) + ":19:"), std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// The real clips.

// An independent look at a real file: the "Frames:" count and the first motion line, read
// with istringstream and strtof.
struct RealFileFacts {
  int frames = 0;
  std::vector<float> first_frame;
};

RealFileFacts scan_real_file(const std::string& text) {
  RealFileFacts facts;
  const size_t frames_at = text.find("Frames:");
  if (frames_at == std::string::npos) return facts;
  facts.frames = std::atoi(text.c_str() + frames_at + 7);
  const size_t time_line_end = text.find('\n', text.find("Frame Time:"));
  const size_t first_line_end = text.find('\n', time_line_end + 1);
  std::istringstream line(text.substr(time_line_end + 1, first_line_end - time_line_end - 1));
  std::string token;
  while (line >> token) facts.first_frame.push_back(std::strtof(token.c_str(), nullptr));
  return facts;
}

const std::vector<std::string> kBandaiJointNames = {
    "joint_Root", "Hips",       "Spine",      "Chest",      "Neck",       "Head",
    "Shoulder_L", "UpperArm_L", "LowerArm_L", "Hand_L",     "Shoulder_R", "UpperArm_R",
    "LowerArm_R", "Hand_R",     "UpperLeg_L", "LowerLeg_L", "Foot_L",     "Toes_L",
    "UpperLeg_R", "LowerLeg_R", "Foot_R",     "Toes_R"};

TEST(BvhRealData, WalkClipMatchesItsHeaderAndFirstLine) {
  const std::filesystem::path path = test::clip_path("dataset-2_walk_normal_001");
  const RealFileFacts facts = scan_real_file(read_file(path));
  ASSERT_EQ(facts.frames, 273);  // checked by hand with `head`/`grep Frames:` on the file
  ASSERT_EQ(facts.first_frame.size(), 22u * 6u);

  Result<Clip> clip = load_bvh(path);
  ASSERT_TRUE(clip.ok()) << clip.message();
  EXPECT_EQ(clip->name, "dataset-2_walk_normal_001");
  EXPECT_EQ(clip->joint_count(), 22);
  EXPECT_EQ(clip->skeleton.names(), kBandaiJointNames);
  EXPECT_EQ(clip->frame_count, facts.frames);
  EXPECT_NEAR(clip->frame_time, 1.0f / 30.0f, 1e-6f);
  EXPECT_TRUE(clip->validate().ok()) << clip->validate().message();

  // Every joint of frame 0 against the independently read first line: positions in metres,
  // rotations Rz * Rx * Ry from "Zrotation Xrotation Yrotation".
  for (int j = 0; j < 22; ++j) {
    SCOPED_TRACE(kBandaiJointNames[j]);
    const float* v = facts.first_frame.data() + 6 * j;
    expect_near_vec(clip->pose(0)[j].translation, glm::vec3(v[0], v[1], v[2]) * 0.01f, 1e-5f);
    expect_near_matrix(glm::mat3_cast(clip->pose(0)[j].rotation),
                       glm::mat3(euler_matrix("ZXY", {v[3], v[4], v[5]})), 2e-5f);
  }

  // The hips stand about 0.9 m above the ground, the head higher, the toes near the ground.
  const std::vector<Transform> global = global_pose(*clip, 0);
  const float hips = global[clip->skeleton.find("Hips")].translation.y;
  EXPECT_GT(hips, 0.8f);
  EXPECT_LT(hips, 1.05f);
  EXPECT_GT(global[clip->skeleton.find("Head")].translation.y, hips + 0.3f);
  EXPECT_LT(global[clip->skeleton.find("Toes_L")].translation.y, 0.2f);
}

TEST(BvhRealData, EveryClipInTheDataFolderParses) {
  std::vector<std::filesystem::path> paths;
  for (const auto& entry : std::filesystem::directory_iterator(test::data_dir())) {
    if (entry.path().extension() == ".bvh") paths.push_back(entry.path());
  }
  std::sort(paths.begin(), paths.end());
  ASSERT_EQ(paths.size(), 472u);
  Skeleton first;
  int64_t total_frames = 0;
  for (const std::filesystem::path& path : paths) {
    Result<Clip> clip = load_bvh(path);
    ASSERT_TRUE(clip.ok()) << clip.message();
    EXPECT_EQ(clip->joint_count(), 22) << path;
    EXPECT_GT(clip->frame_count, 0) << path;
    EXPECT_NEAR(clip->frame_time, 1.0f / 30.0f, 1e-6f) << path;
    if (first.joint_count() == 0) first = clip->skeleton;
    EXPECT_TRUE(clip->skeleton.same_topology(first)) << path;
    total_frames += clip->frame_count;
  }
  // The data README's count for bandai-normal.
  EXPECT_EQ(total_frames, 54638);
}

// Debian's assimp-testmodels (installed by scripts/setup.sh): Blender and assimp read this file,
// whose "Frames: 3069" (line 128) is followed by 3070 frame lines (130 to 3199).
TEST(BvhRealData, AssimpBoxingToesLoadsItsDeclaredFramesWithOneWarning) {
  const std::filesystem::path path = "/usr/share/assimp/models/BVH/Boxing_Toes.bvh";
  ASSERT_TRUE(std::filesystem::is_regular_file(path))
      << path << " is missing: install Debian's assimp-testmodels (scripts/setup.sh)";
  const std::string text = read_file(path);
  ASSERT_EQ(scan_real_file(text).frames, 3069);
  ASSERT_EQ(last_line_number(text), 3200);  // ends with a newline after line 3199
  // The last declared frame, line 3198, read independently: the root's position channels.
  size_t line_start = 0;
  for (int line = 1; line < 3198; ++line) line_start = text.find('\n', line_start) + 1;
  std::istringstream last(text.substr(line_start, text.find('\n', line_start) - line_start));
  float root[3] = {0.0f, 0.0f, 0.0f};
  last >> root[0] >> root[1] >> root[2];
  ASSERT_FALSE(last.fail());

  Result<Clip> clip = load_bvh(path);
  ASSERT_TRUE(clip.ok()) << clip.message();
  EXPECT_EQ(clip->frame_count, 3069);
  EXPECT_EQ(clip->joint_count(), 21);
  EXPECT_TRUE(clip->validate().ok()) << clip->validate().message();
  ASSERT_EQ(clip->warnings.size(), 1u);
  EXPECT_EQ(clip->warnings[0],
            path.string() + ":3199: ignored 1 frame line beyond 'Frames: 3069' on line 128");
  expect_near_vec(clip->pose(3068)[0].translation, glm::vec3(root[0], root[1], root[2]) * 0.01f,
                  1e-5f);
}

TEST(BvhRealData, SetOneClipsWithSpaceIndentationParse) {
  std::vector<std::filesystem::path> paths;
  for (const auto& entry : std::filesystem::directory_iterator(test::data_dir())) {
    if (entry.path().filename().string().rfind("dataset-1_", 0) == 0) paths.push_back(entry.path());
  }
  ASSERT_EQ(paths.size(), 7u);
  for (const std::filesystem::path& path : paths) {
    SCOPED_TRACE(path.string());
    const std::string text = read_file(path);
    ASSERT_NE(text.find("\n  OFFSET"), std::string::npos);  // spaces, not tabs
    const RealFileFacts facts = scan_real_file(text);
    Result<Clip> clip = load_bvh(path);
    ASSERT_TRUE(clip.ok()) << clip.message();
    EXPECT_EQ(clip->skeleton.names(), kBandaiJointNames);
    EXPECT_EQ(clip->frame_count, facts.frames);
    EXPECT_TRUE(clip->validate().ok()) << clip->validate().message();
    const float* v = facts.first_frame.data() + 6;  // Hips
    expect_near_vec(clip->pose(0)[1].translation, glm::vec3(v[0], v[1], v[2]) * 0.01f, 1e-5f);
  }
  // In walk-back the root itself translates: its position channels are kept, not assumed zero.
  Result<Clip> back = load_bvh(test::clip_path("dataset-1_walk-back_normal_001"));
  ASSERT_TRUE(back.ok()) << back.message();
  float largest_root_offset = 0.0f;
  for (int f = 0; f < back->frame_count; ++f) {
    largest_root_offset = std::max(largest_root_offset, glm::length(back->pose(f)[0].translation));
  }
  EXPECT_GT(largest_root_offset, 0.01f);
}

}  // namespace
}  // namespace mm
