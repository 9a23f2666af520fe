// Clip tags: glob matching, the manifest format and its errors, tags from Bandai file names,
// and the left/right swap of mirrored clips.

#include <gtest/gtest.h>

#include <fstream>

#include "mm/offline/tags.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

using Tags = std::vector<std::string>;

TEST(Glob, StarAndQuestionMark) {
  EXPECT_TRUE(glob_match("*", ""));
  EXPECT_TRUE(glob_match("*", "anything"));
  EXPECT_TRUE(glob_match("dataset-2_walk_*", "dataset-2_walk_normal_001"));
  EXPECT_FALSE(glob_match("dataset-2_walk_*", "dataset-2_walk-turn-left_normal_001"));
  EXPECT_TRUE(glob_match("*_walk*_normal_00?", "dataset-2_walk-turn-left_normal_003"));
  EXPECT_FALSE(glob_match("*_normal_00?", "dataset-2_walk_normal_0031"));
  EXPECT_TRUE(glob_match("a*b*c", "aXXbYYbZc"));
  EXPECT_FALSE(glob_match("a*b*c", "aXXbYYbZ"));
  EXPECT_TRUE(glob_match("exact", "exact"));
  EXPECT_FALSE(glob_match("exact", "exactly"));
  EXPECT_FALSE(glob_match("?", ""));
  EXPECT_TRUE(glob_match("**a**", "a"));
}

TEST(TagManifest, ParsesRulesCommentsAndBlankLines) {
  const char* text =
      "# tags for the demo\n"
      "\n"
      "*_walk_*   gait-walk  calm   # trailing comment\n"
      "\t*run*\tfast\r\n"
      "   \n";
  Result<std::vector<TagRule>> rules = parse_tag_manifest(text, "tags.txt");
  ASSERT_TRUE(rules) << rules.message();
  ASSERT_EQ(rules->size(), 2u);
  EXPECT_EQ((*rules)[0].pattern, "*_walk_*");
  EXPECT_EQ((*rules)[0].tags, (Tags{"gait-walk", "calm"}));
  EXPECT_EQ((*rules)[0].line, 3);
  EXPECT_EQ((*rules)[1].pattern, "*run*");
  EXPECT_EQ((*rules)[1].tags, (Tags{"fast"}));
  EXPECT_EQ((*rules)[1].line, 4);
}

TEST(TagManifest, ErrorsNameTheFileAndLine) {
  Result<std::vector<TagRule>> rules = parse_tag_manifest("*_walk_* walk\nlonely\n", "my.tags");
  ASSERT_FALSE(rules);
  EXPECT_NE(rules.message().find("my.tags:2:"), std::string::npos) << rules.message();
  EXPECT_NE(rules.message().find("lonely"), std::string::npos) << rules.message();
  rules = parse_tag_manifest("\n\n* bad/tag\n", "my.tags");
  ASSERT_FALSE(rules);
  EXPECT_NE(rules.message().find("my.tags:3:"), std::string::npos) << rules.message();
  EXPECT_NE(rules.message().find("'/'"), std::string::npos) << rules.message();
  Result<std::vector<TagRule>> missing = load_tag_manifest(test::scratch_dir() / "none.tags");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.message().find("none.tags"), std::string::npos);
}

TEST(TagManifest, LoadsFromAFile) {
  const auto path = test::scratch_dir() / "t.tags";
  std::ofstream(path) << "dataset-2_wave-* gesture\n";
  Result<std::vector<TagRule>> rules = load_tag_manifest(path);
  ASSERT_TRUE(rules) << rules.message();
  ASSERT_EQ(rules->size(), 1u);
  EXPECT_EQ((*rules)[0].tags, (Tags{"gesture"}));
}

TEST(TagsFromName, BandaiNames) {
  EXPECT_EQ(tags_from_name("dataset-2_walk_normal_001"), (Tags{"locomotion", "normal", "walk"}));
  EXPECT_EQ(tags_from_name("dataset-2_walk-turn-left_normal_031"),
            (Tags{"locomotion", "normal", "walk", "walk-turn-left"}));
  EXPECT_EQ(tags_from_name("dataset-1_run_not-confident_002"),
            (Tags{"locomotion", "not-confident", "run"}));
  EXPECT_EQ(tags_from_name("dataset-1_dash_normal_001"), (Tags{"dash", "locomotion", "normal"}));
  EXPECT_EQ(tags_from_name("dataset-2_wave-left-hand_normal_010"),
            (Tags{"action", "normal", "wave-left-hand"}));
  EXPECT_EQ(tags_from_name("dataset-2_raise-up-both-hands_tired_001"),
            (Tags{"action", "raise-up-both-hands", "tired"}));
  // Not Bandai names: nothing.
  EXPECT_TRUE(tags_from_name("walk01").empty());
  EXPECT_TRUE(tags_from_name("dataset-2_walk_normal").empty());
  EXPECT_TRUE(tags_from_name("dataset-x_walk_normal_001").empty());
  EXPECT_TRUE(tags_from_name("dataset-2_walk_normal_00a").empty());
}

TEST(ClipTags, ManifestAddsAndMirrorSwapsSides) {
  Result<std::vector<TagRule>> rules =
      parse_tag_manifest("*turn-left* curve\n*_walk-turn-* turning left-leaning\n", "x");
  ASSERT_TRUE(rules);
  const std::string name = "dataset-2_walk-turn-left_normal_001";
  EXPECT_EQ(clip_tags(name, false, *rules), (Tags{"curve", "left-leaning", "locomotion", "normal",
                                                  "turning", "walk", "walk-turn-left"}));
  EXPECT_EQ(clip_tags(name, true, *rules),
            (Tags{"curve", "locomotion", "mirrored", "normal", "right-leaning", "turning", "walk",
                  "walk-turn-right"}));
  EXPECT_EQ(clip_tags("custom_take", false, *rules), Tags{});
  EXPECT_EQ(clip_tags("custom_take", true, {}), Tags{"mirrored"});
}

TEST(ClipTags, SwapLeftRight) {
  EXPECT_EQ(swap_left_right("wave-left-hand"), "wave-right-hand");
  EXPECT_EQ(swap_left_right("right"), "left");
  EXPECT_EQ(swap_left_right("LeftRight"), "RightLeft");
  EXPECT_EQ(swap_left_right("turnLeft"), "turnRight");
  EXPECT_EQ(swap_left_right("left_right.left"), "right_left.right");
  // Only whole words: these stay.
  EXPECT_EQ(swap_left_right("straight"), "straight");
  EXPECT_EQ(swap_left_right("leftover"), "leftover");
  EXPECT_EQ(swap_left_right("bright-light"), "bright-light");
}

TEST(TagsFromName, ReActIdleNamesAreIdle) {
  EXPECT_EQ(tags_from_name("003_genuine"),
            (std::vector<std::string>{"idle", "reactidle", "genuine"}));
  EXPECT_EQ(tags_from_name("012_acted"), (std::vector<std::string>{"idle", "reactidle", "acted"}));
  EXPECT_TRUE(tags_from_name("x03_genuine").empty());
  EXPECT_TRUE(tags_from_name("003_genuinely").empty());
}

}  // namespace
}  // namespace mm

namespace mm {
namespace {

using StyleTags = std::vector<std::string>;

TEST(ClipStyle, FromBandaiNamesAndManifestLines) {
  EXPECT_EQ(clip_style("dataset-1_run_not-confident_002", {}), "not-confident");
  EXPECT_EQ(clip_style("dataset-2_walk-turn-left_elderly_031", {}), "elderly");
  EXPECT_EQ(clip_style("003_genuine", {}), "");  // idle: serves every style
  EXPECT_EQ(clip_style("my_walk", {}), "");
  auto rules = parse_tag_manifest("my_* walk style=sneaky\nmy_run* style=hurried\n", "m.txt");
  ASSERT_TRUE(rules) << rules.message();
  EXPECT_EQ(clip_style("my_walk", *rules), "sneaky");
  EXPECT_EQ(clip_style("my_run_01", *rules), "hurried");  // the last matching line wins
  // The style is a tag too (its search filter bit), and "style=..." is not a tag.
  EXPECT_EQ(clip_tags("my_walk", false, *rules), (StyleTags{"sneaky", "walk"}));
}

TEST(ClipStyle, BadManifestStylesAreRefusedWithTheLine) {
  auto empty = parse_tag_manifest("a* walk style=\n", "m.txt");
  ASSERT_FALSE(empty);
  EXPECT_NE(empty.message().find("m.txt:1: expected style=NAME with a name of letters"),
            std::string::npos)
      << empty.message();
  auto twice = parse_tag_manifest("\na* style=x style=y\n", "m.txt");
  ASSERT_FALSE(twice);
  EXPECT_NE(twice.message().find("m.txt:2: two styles on one line"), std::string::npos)
      << twice.message();
}

}  // namespace
}  // namespace mm
