#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <numbers>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "mm/controller/script.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kDegree = std::numbers::pi_v<float> / 180.0f;

InputScript parse_ok(std::string_view text) {
  Result<InputScript> script = parse_input_script(text, "test.txt");
  EXPECT_TRUE(script.ok()) << (script ? "" : script.message());
  return script ? std::move(script).value() : InputScript();
}

std::string parse_error(std::string_view text, std::string_view name = "walk.txt") {
  Result<InputScript> script = parse_input_script(text, name);
  return script ? std::string("(parsed)") : script.message();
}

// Every field of two inputs, the tag by its text.
void expect_same_input(const ControllerInput& a, const ControllerInput& b) {
  EXPECT_EQ(a.left_stick, b.left_stick);
  EXPECT_EQ(a.right_stick, b.right_stick);
  EXPECT_EQ(a.camera_yaw, b.camera_yaw);
  EXPECT_EQ(a.run, b.run);
  EXPECT_EQ(a.strafe, b.strafe);
  EXPECT_EQ(a.tag, b.tag);
}

void expect_neutral(const ControllerInput& input) {
  expect_same_input(input, ControllerInput{});
}

// Each event's view points into its own `tag` string, not merely at equal text elsewhere.
void expect_views_own_tags(const InputScript& script) {
  for (const ScriptEvent& e : script.events()) {
    EXPECT_EQ(e.input.tag, e.tag) << "line " << e.line;
    if (!e.tag.empty()) {
      EXPECT_EQ(e.input.tag.data(), e.tag.data()) << "line " << e.line;
    }
  }
}

const char* const kValid =
    "# a header comment\n"
    "0.5 0.25 -1 1 -0.5 run strafe tag=wave camera=90\n"
    "\n"
    "1.0\t0 1  0 0   camera=-45.5 run   # flags in any order, tabs and runs of spaces\n"
    "2 -0.75 0.5 0 0 tag=wave-both_hands.v2:x+y strafe\n";

// ---------------------------------------------------------------------------------------------
// Parsing valid text.

TEST(InputScript, ParsesEveryFieldAndFlag) {
  const InputScript script = parse_ok(kValid);
  ASSERT_EQ(script.events().size(), 3u);

  const ScriptEvent& a = script.events()[0];
  EXPECT_EQ(a.line, 2);
  EXPECT_EQ(a.time, 0.5f);
  EXPECT_EQ(a.input.left_stick, glm::vec2(0.25f, -1.0f));
  EXPECT_EQ(a.input.right_stick, glm::vec2(1.0f, -0.5f));
  EXPECT_TRUE(a.input.run);
  EXPECT_TRUE(a.input.strafe);
  EXPECT_EQ(a.tag, "wave");
  EXPECT_EQ(a.input.tag, "wave");
  EXPECT_NEAR(a.input.camera_yaw, std::numbers::pi_v<float> / 2.0f, 1e-6f);  // degrees in the file

  const ScriptEvent& b = script.events()[1];
  EXPECT_EQ(b.line, 4);
  EXPECT_EQ(b.time, 1.0f);
  EXPECT_EQ(b.input.left_stick, glm::vec2(0.0f, 1.0f));
  EXPECT_EQ(b.input.right_stick, glm::vec2(0.0f, 0.0f));
  EXPECT_TRUE(b.input.run);
  EXPECT_FALSE(b.input.strafe);
  EXPECT_TRUE(b.tag.empty());
  EXPECT_TRUE(b.input.tag.empty());
  EXPECT_NEAR(b.input.camera_yaw, -45.5f * kDegree, 1e-6f);

  const ScriptEvent& c = script.events()[2];
  EXPECT_EQ(c.line, 5);
  EXPECT_EQ(c.time, 2.0f);
  EXPECT_EQ(c.input.left_stick, glm::vec2(-0.75f, 0.5f));
  EXPECT_FALSE(c.input.run);
  EXPECT_TRUE(c.input.strafe);
  EXPECT_EQ(c.input.tag, "wave-both_hands.v2:x+y");  // every tag character
  EXPECT_EQ(c.input.camera_yaw, 0.0f);               // absent: 0

  EXPECT_EQ(script.duration(), 2.0f);
  expect_views_own_tags(script);
}

TEST(InputScript, NumbersInEveryWrittenForm) {
  const InputScript script = parse_ok(
      "0 .5 -.5 1e-1 -1.0\n"
      "+1.25 +0.5 1. -0 0\n"
      "1.25 0 0 0 0 camera=+1e2\n");
  ASSERT_EQ(script.events().size(), 3u);
  EXPECT_EQ(script.events()[0].input.left_stick, glm::vec2(0.5f, -0.5f));
  EXPECT_EQ(script.events()[0].input.right_stick, glm::vec2(0.1f, -1.0f));
  EXPECT_EQ(script.events()[1].time, 1.25f);
  EXPECT_EQ(script.events()[1].input.left_stick, glm::vec2(0.5f, 1.0f));
  EXPECT_FALSE(std::signbit(script.events()[1].input.right_stick.x));  // "-0" is 0
  EXPECT_NEAR(script.events()[2].input.camera_yaw, 100.0f * kDegree, 1e-6f);
}

TEST(InputScript, CommentsBlankLinesAndLineEndsAreIgnored) {
  const InputScript script = parse_ok(
      "# only a comment\r\n"
      "   \t  \r\n"
      "\r\n"
      "   # an indented comment\n"
      "1 0 1 0 0 run#a comment right after a flag\r\n"
      "2 0 0 0 0 # released\n"
      "\n"
      "#3 0 1 0 0 a line commented out\n"
      "3 1 0 0 0");  // no final line end
  ASSERT_EQ(script.events().size(), 3u);
  EXPECT_EQ(script.events()[0].line, 5);
  EXPECT_TRUE(script.events()[0].input.run);
  EXPECT_EQ(script.events()[1].line, 6);
  EXPECT_EQ(script.events()[2].line, 9);
  EXPECT_EQ(script.events()[2].input.left_stick, glm::vec2(1.0f, 0.0f));

  // A byte order mark, as some Windows editors write, is not part of the first token.
  const InputScript marked = parse_ok(
      "\xEF\xBB\xBF"
      "1 0 1 0 0\n");
  ASSERT_EQ(marked.events().size(), 1u);
  EXPECT_EQ(marked.events()[0].time, 1.0f);

  // Nothing but comments is an empty script, neutral at every time.
  const InputScript empty = parse_ok("# nothing yet\n\n");
  EXPECT_TRUE(empty.events().empty());
  EXPECT_EQ(empty.duration(), 0.0f);
  EXPECT_EQ(empty.index_at(5.0f), -1);
  expect_neutral(empty.at(5.0f));
  EXPECT_TRUE(parse_ok("").events().empty());
}

// ---------------------------------------------------------------------------------------------
// The input in effect at a time.

TEST(InputScript, AtBeforeBetweenAndAfterTheLines) {
  const InputScript script = parse_ok(
      "1 0 1 0 0 camera=30\n"
      "2.5 1 0 0 0 run\n"
      "4 0 0 0 0 tag=wave\n");
  // Before the first line: neutral, including the camera.
  EXPECT_EQ(script.index_at(0.0f), -1);
  EXPECT_EQ(script.index_at(0.999f), -1);
  EXPECT_EQ(script.index_at(-kInf), -1);
  expect_neutral(script.at(0.5f));
  expect_neutral(script.at(-3.0f));
  // A line takes effect at its own time and holds until the next.
  EXPECT_EQ(script.index_at(1.0f), 0);
  EXPECT_EQ(script.index_at(2.4999f), 0);
  EXPECT_EQ(script.at(1.0f).left_stick, glm::vec2(0.0f, 1.0f));
  EXPECT_NEAR(script.at(2.0f).camera_yaw, 30.0f * kDegree, 1e-6f);
  EXPECT_EQ(script.index_at(2.5f), 1);
  EXPECT_TRUE(script.at(3.0f).run);
  EXPECT_EQ(script.at(3.0f).camera_yaw, 0.0f);  // every line is a whole state
  // The last line holds forever.
  EXPECT_EQ(script.index_at(4.0f), 2);
  EXPECT_EQ(script.index_at(1e6f), 2);
  EXPECT_EQ(script.index_at(kInf), 2);
  EXPECT_EQ(script.at(100.0f).tag, "wave");
  EXPECT_EQ(script.at(100.0f).tag.data(), script.events()[2].tag.data());
  EXPECT_FALSE(script.at(100.0f).run);
  // A NaN time is no time: neutral rather than an arbitrary line.
  EXPECT_EQ(script.index_at(kNaN), -1);
  expect_neutral(script.at(kNaN));
  EXPECT_EQ(script.duration(), 4.0f);
}

TEST(InputScript, OfEqualTimesTheLaterLineWins) {
  const InputScript script = parse_ok(
      "0 0 0 0 0\n"
      "1 0 1 0 0\n"
      "1 1 0 0 0 run\n"
      "1 -1 0 0 0 strafe\n"
      "2 0 -1 0 0\n");
  EXPECT_EQ(script.index_at(0.99f), 0);
  EXPECT_EQ(script.index_at(1.0f), 3);
  EXPECT_EQ(script.at(1.0f).left_stick, glm::vec2(-1.0f, 0.0f));
  EXPECT_TRUE(script.at(1.5f).strafe);
  EXPECT_FALSE(script.at(1.5f).run);
  EXPECT_EQ(script.index_at(2.0f), 4);

  // Equal times at the start too.
  const InputScript start = parse_ok("0 1 0 0 0\n0 0 1 0 0\n");
  EXPECT_EQ(start.index_at(0.0f), 1);
  EXPECT_EQ(start.at(0.0f).left_stick, glm::vec2(0.0f, 1.0f));
}

// ---------------------------------------------------------------------------------------------
// Refusals: each names the file, the line and what was expected there.

TEST(InputScript, EveryMalformedLineIsRefusedWithItsMessage) {
  struct Case {
    const char* text;
    const char* message;
  };
  const Case cases[] = {
      // Not a number, on the third line: the comment and the blank line count as lines.
      {"# walk\n\n0 abc 0 0 0\n",
       "walk.txt:3: expected the left stick's x (a number in [-1, 1]), found 'abc'"},
      // Missing fields.
      {"1\n",
       "walk.txt:1: expected the left stick's x (a number in [-1, 1]), found the end of the line"},
      {"1 0\n",
       "walk.txt:1: expected the left stick's y (a number in [-1, 1]), found the end of the line"},
      {"1 0 0\n",
       "walk.txt:1: expected the right stick's x (a number in [-1, 1]), found the end of the line"},
      {"1 0 0 0 # the comment is not a field\n",
       "walk.txt:1: expected the right stick's y (a number in [-1, 1]), found the end of the line"},
      {"run 0 0 0 0\n",
       "walk.txt:1: expected the time in seconds (a number in [0, 28800], the longest script), "
       "found 'run'"},
      // Not numbers, or not whole numbers.
      {"0 0,5 0 0 0\n",
       "walk.txt:1: expected the left stick's x (a number in [-1, 1]), found '0,5'"},
      {"0 0 0.5x 0 0\n",
       "walk.txt:1: expected the left stick's y (a number in [-1, 1]), found '0.5x'"},
      {"0 0 0 0x1 0\n",
       "walk.txt:1: expected the right stick's x (a number in [-1, 1]), found '0x1'"},
      {"0 0 0 0 --1\n",
       "walk.txt:1: expected the right stick's y (a number in [-1, 1]), found '--1'"},
      {"0 0 0 +-1 0\n",
       "walk.txt:1: expected the right stick's x (a number in [-1, 1]), found '+-1'"},
      {"0 0 0 + 0\n", "walk.txt:1: expected the right stick's x (a number in [-1, 1]), found '+'"},
      {"1s 0 0 0 0\n",
       "walk.txt:1: expected the time in seconds (a number in [0, 28800], the longest script), "
       "found '1s'"},
      // Sticks out of range, each naming its field.
      {"0 1.5 0 0 0\n",
       "walk.txt:1: expected the left stick's x (a number in [-1, 1]), found '1.5'"},
      {"0 0 -1.01 0 0\n",
       "walk.txt:1: expected the left stick's y (a number in [-1, 1]), found '-1.01'"},
      {"0 0 0 2 0\n", "walk.txt:1: expected the right stick's x (a number in [-1, 1]), found '2'"},
      {"0 0 0 0 -7\n",
       "walk.txt:1: expected the right stick's y (a number in [-1, 1]), found '-7'"},
      // Not finite.
      {"nan 0 0 0 0\n",
       "walk.txt:1: expected the time in seconds (a number in [0, 28800], the longest script), "
       "found 'nan'"},
      {"inf 0 0 0 0\n",
       "walk.txt:1: expected the time in seconds (a number in [0, 28800], the longest script), "
       "found 'inf'"},
      {"1e39 0 0 0 0\n",
       "walk.txt:1: expected the time in seconds (a number in [0, 28800], the longest script), "
       "found '1e39'"},
      {"0 NaN 0 0 0\n",
       "walk.txt:1: expected the left stick's x (a number in [-1, 1]), found 'NaN'"},
      {"0 0 -infinity 0 0\n",
       "walk.txt:1: expected the left stick's y (a number in [-1, 1]), found '-infinity'"},
      // Negative and decreasing time.
      {"-1 0 0 0 0\n",
       "walk.txt:1: expected the time in seconds (a number in [0, 28800], the longest script), "
       "found '-1'"},
      {"-0.001 0 0 0 0\n",
       "walk.txt:1: expected the time in seconds (a number in [0, 28800], the longest script), "
       "found '-0.001'"},
      {"2.5 0 0 0 0\n# pause\n1 0 0 0 0\n",
       "walk.txt:3: expected a time >= 2.5 (the time of line 1), found '1'"},
      {"0 0 0 0 0\n3 0 0 0 0\n3 0 1 0 0\n2.999 0 0 0 0\n",
       "walk.txt:4: expected a time >= 3 (the time of line 3), found '2.999'"},
      // Unknown words.
      {"0 0 0 0 0 jump\n",
       "walk.txt:1: expected run, strafe, tag=NAME, style=NAME or camera=DEGREES, found 'jump'"},
      {"0 0 0 0 0 0.5\n",
       "walk.txt:1: expected run, strafe, tag=NAME, style=NAME or camera=DEGREES, found '0.5'"},
      {"0 0 0 0 0 Run\n",
       "walk.txt:1: expected run, strafe, tag=NAME, style=NAME or camera=DEGREES, found 'Run'"},
      {"0 0 0 0 0 running\n",
       "walk.txt:1: expected run, strafe, tag=NAME, style=NAME or camera=DEGREES, found 'running'"},
      {"0 0 0 0 0 tag\n",
       "walk.txt:1: expected run, strafe, tag=NAME, style=NAME or camera=DEGREES, found 'tag'"},
      {"0 0 0 0 0 camera\n",
       "walk.txt:1: expected run, strafe, tag=NAME, style=NAME or camera=DEGREES, found 'camera'"},
      {"0 0 0 0 0 yaw=90\n",
       "walk.txt:1: expected run, strafe, tag=NAME, style=NAME or camera=DEGREES, found 'yaw=90'"},
      {"0 0 0 0 0 style=\n",
       "walk.txt:1: expected style=NAME with a name of letters, digits and _-.:+, found 'style='"},
      {"0 0 0 0 0 style=a style=b\n",
       "walk.txt:1: expected style=NAME at most once on a line, found 'style=b' again"},
      // Duplicate flags.
      {"0 0 0 0 0 run strafe run\n",
       "walk.txt:1: expected run at most once on a line, found 'run' again"},
      {"0 0 0 0 0 strafe strafe\n",
       "walk.txt:1: expected strafe at most once on a line, found 'strafe' again"},
      {"0 0 0 0 0 tag=wave run tag=bow\n",
       "walk.txt:1: expected tag=NAME at most once on a line, found 'tag=bow' again"},
      {"0 0 0 0 0 camera=0 camera=90\n",
       "walk.txt:1: expected camera=DEGREES at most once on a line, found 'camera=90' again"},
      // Tags: empty, or with a character outside letters, digits and _-.:+
      {"0 0 0 0 0 tag=\n",
       "walk.txt:1: expected tag=NAME with a name of letters, digits and _-.:+, found 'tag='"},
      {"0 0 0 0 0 tag=wa/ve\n",
       "walk.txt:1: expected tag=NAME with a name of letters, digits and _-.:+, found 'tag=wa/ve'"},
      {"0 0 0 0 0 tag=wave!\n",
       "walk.txt:1: expected tag=NAME with a name of letters, digits and _-.:+, found 'tag=wave!'"},
      {"0 0 0 0 0 tag=tag=wave\n",
       "walk.txt:1: expected tag=NAME with a name of letters, digits and _-.:+, found "
       "'tag=tag=wave'"},
      {"0 0 0 0 0 tag=w\xc3\xa4ve\n",
       "walk.txt:1: expected tag=NAME with a name of letters, digits and _-.:+, found "
       "'tag=w\xc3\xa4ve'"},
      // Camera: a finite number of degrees.
      {"0 0 0 0 0 camera=\n",
       "walk.txt:1: expected camera=DEGREES with a finite number of degrees, found 'camera='"},
      {"0 0 0 0 0 camera=abc\n",
       "walk.txt:1: expected camera=DEGREES with a finite number of degrees, found 'camera=abc'"},
      {"0 0 0 0 0 camera=nan\n",
       "walk.txt:1: expected camera=DEGREES with a finite number of degrees, found 'camera=nan'"},
      {"0 0 0 0 0 camera=-inf\n",
       "walk.txt:1: expected camera=DEGREES with a finite number of degrees, found 'camera=-inf'"},
      {"0 0 0 0 0 camera=90deg\n",
       "walk.txt:1: expected camera=DEGREES with a finite number of degrees, found 'camera=90deg'"},
      {"0 0 0 0 0 camera=1e39\n",
       "walk.txt:1: expected camera=DEGREES with a finite number of degrees, found 'camera=1e39'"},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(parse_error(c.text), c.message) << "text: " << c.text;
  }
}

TEST(InputScript, MessagesGiveTheNameAndTheLineOfALongFile) {
  std::string text = "# header\n";
  for (int i = 0; i < 40; ++i) text += std::to_string(i) + " 0 1 0 0\n";
  text += "40 0 1 0 0 walk\n";  // line 42
  EXPECT_EQ(parse_error(text, "scripts/input/long.txt"),
            "scripts/input/long.txt:42: expected run, strafe, tag=NAME, style=NAME or "
            "camera=DEGREES, found "
            "'walk'");
  // The first malformed line is the one reported.
  EXPECT_EQ(parse_error("0 0 0 0 0\n1 x 0 0 0\n2 y 0 0 0\n", "a.txt"),
            "a.txt:2: expected the left stick's x (a number in [-1, 1]), found 'x'");
}

// Bounded runs (script.hpp): a time past kMaxScriptSeconds is refused at parse, by file and
// line, before a run could try to turn it into a frame count.
TEST(InputScript, TimesPastTheLongestScriptAreRefusedByFileAndLine) {
  EXPECT_EQ(parse_error("0 0 1 0 0\n1e30 0 0 0 0\n", "far.txt"),
            "far.txt:2: expected the time in seconds (a number in [0, 28800], the longest "
            "script), found '1e30'");
  EXPECT_EQ(parse_error("0 0 1 0 0\n# a million seconds\n1e6 0 0 0 0\n", "long.txt"),
            "long.txt:3: expected the time in seconds (a number in [0, 28800], the longest "
            "script), found '1e6'");
  EXPECT_EQ(parse_error("28800.01 0 0 0 0\n", "long.txt"),
            "long.txt:1: expected the time in seconds (a number in [0, 28800], the longest "
            "script), found '28800.01'");
  // The limit itself is a time a script may have.
  const InputScript longest = parse_ok("0 0 1 0 0\n28800 0 0 0 0\n");
  EXPECT_EQ(longest.duration(), kMaxScriptSeconds);
}

TEST(InputScript, RunFramesAreTheCeilingOfSecondsOverDt) {
  EXPECT_EQ(*scripted_run_frames(8.0f, 0.02f), 400);
  EXPECT_EQ(*scripted_run_frames(0.0f, 0.02f), 0);
  EXPECT_EQ(*scripted_run_frames(1.0f, 0.3f), 4);
  // The longest script at 1/144 s, with the 2 s mm eval adds, fits the frame limit.
  EXPECT_TRUE(scripted_run_frames(kMaxScriptSeconds + 2.0f, 1.0f / 144.0f).ok());
}

TEST(InputScript, RunsOutsideTheLimitsAreRefusedWithTheirValues) {
  auto message = [](float seconds, float dt) {
    const Result<int> frames = scripted_run_frames(seconds, dt);
    return frames ? std::string("(accepted)") : frames.message();
  };
  EXPECT_EQ(message(18.0f, 1e-6f), "the time step must be in [0.0001, 1] seconds, found 1e-06");
  EXPECT_EQ(message(18.0f, 0.0f), "the time step must be in [0.0001, 1] seconds, found 0");
  EXPECT_EQ(message(18.0f, -0.01f), "the time step must be in [0.0001, 1] seconds, found -0.01");
  EXPECT_EQ(message(18.0f, 2.0f), "the time step must be in [0.0001, 1] seconds, found 2");
  EXPECT_EQ(message(18.0f, kNaN), "the time step must be in [0.0001, 1] seconds, found nan");
  EXPECT_EQ(message(18.0f, kInf), "the time step must be in [0.0001, 1] seconds, found inf");
  EXPECT_EQ(message(kInf, 0.01f),
            "the run length must be a finite number of seconds >= 0, found inf");
  EXPECT_EQ(message(-1.0f, 0.01f),
            "the run length must be a finite number of seconds >= 0, found -1");
  // The longest script at the smallest step: 288 million frames.
  EXPECT_EQ(message(28800.0f, 1e-4f),
            "a run of 28800 s at a time step of 0.0001 s needs 288000000 frames, more than the "
            "limit of 4194304");
  // Far past int: refused, not converted.
  EXPECT_EQ(message(1e30f, 0.01f),
            "a run of 1e+30 s at a time step of 0.01 s needs 1e+32 frames, more than the limit "
            "of 4194304");
}

TEST(InputScript, ALongTokenIsCutInTheMessage) {
  const std::string token(500, 'z');
  const std::string message = parse_error("0 0 0 0 0 " + token + "\n");
  EXPECT_EQ(message,
            "walk.txt:1: expected run, strafe, tag=NAME, style=NAME or camera=DEGREES, found '" +
                std::string(40, 'z') + "...'");
}

// ---------------------------------------------------------------------------------------------
// Tag views: a ScriptEvent's input.tag views its own `tag`, in every copy.

TEST(InputScript, CopiesKeepTheirTagViewsValid) {
  // Short tags live inside the string object (small-string storage), so a copied view would
  // point into the original's events; long ones live on the heap. Test both.
  const std::string long_tag(64, 'w');
  const std::string text = "0 0 1 0 0 tag=wave\n1 0 0 0 0\n2 1 0 0 0 tag=" + long_tag + "\n";
  auto original = std::make_unique<InputScript>(parse_ok(text));
  expect_views_own_tags(*original);

  const InputScript copied(*original);  // copy constructor
  InputScript assigned = parse_ok("0 0 0 0 0 tag=old\n");
  assigned = *original;  // copy assignment over a script that had tags of its own
  InputScript self = parse_ok(text);
  const InputScript& alias = self;
  self = alias;  // self-assignment changes nothing
  original.reset();

  const InputScript* const copies[] = {&copied, &assigned, &self};
  for (const InputScript* script : copies) {
    ASSERT_EQ(script->events().size(), 3u);
    expect_views_own_tags(*script);
    EXPECT_EQ(script->at(0.5f).tag, "wave");
    EXPECT_EQ(script->at(1.5f).tag, "");
    EXPECT_EQ(script->at(3.0f).tag, long_tag);
  }

  // Moves keep the events' storage, so their views stay valid too.
  InputScript moved(std::move(self));
  expect_views_own_tags(moved);
  EXPECT_EQ(moved.at(0.0f).tag, "wave");
  InputScript move_assigned;
  move_assigned = std::move(moved);
  expect_views_own_tags(move_assigned);
  EXPECT_EQ(move_assigned.at(2.0f).tag, long_tag);
}

TEST(InputScript, TheVectorConstructorPointsViewsAtTheOwnedTags) {
  std::vector<ScriptEvent> events(3);
  events[0].time = 0.0f;
  events[0].tag = "wave";
  events[1].time = 1.0f;
  events[1].tag = "bow";
  events[1].input.tag = "a view the constructor replaces";
  events[2].time = 1.0f;
  events[2].input.run = true;
  // Copies of the events whose views point into the vector above, which then goes away.
  auto source = std::make_unique<std::vector<ScriptEvent>>(events);
  for (size_t i = 0; i < events.size(); ++i) (*source)[i].input.tag = (*source)[i].tag;
  std::vector<ScriptEvent> copies = *source;
  source.reset();

  const InputScript script(std::move(copies));
  expect_views_own_tags(script);
  EXPECT_EQ(script.at(0.5f).tag, "wave");
  EXPECT_EQ(script.index_at(1.0f), 2);
  EXPECT_EQ(script.at(1.0f).tag, "");
  EXPECT_TRUE(script.at(1.0f).run);
  EXPECT_EQ(script.duration(), 1.0f);
}

// ---------------------------------------------------------------------------------------------
// Formatting a line, and reading it back.

TEST(InputScript, FormatPrintsTheDocumentedLine) {
  ControllerInput input;
  input.left_stick = {0.0f, 1.0f};
  input.run = true;
  input.tag = "wave";
  input.camera_yaw = std::numbers::pi_v<float> / 2.0f;
  EXPECT_EQ(format_script_line(1.5f, input),
            "1.500 0.000 1.000 0.000 0.000 run tag=wave camera=90.0");

  EXPECT_EQ(format_script_line(0.0f, ControllerInput{}), "0.000 0.000 0.000 0.000 0.000");

  ControllerInput all;
  all.left_stick = {-0.25f, 0.3333333f};
  all.right_stick = {1.0f, -1.0f};
  all.run = true;
  all.strafe = true;
  all.tag = "wave-both-hands";
  all.camera_yaw = -135.04f * kDegree;
  EXPECT_EQ(format_script_line(12.3456f, all),
            "12.346 -0.250 0.333 1.000 -1.000 run strafe tag=wave-both-hands camera=-135.0");
  EXPECT_EQ(format_script_line(2.0f, input, "not-confident"),
            "2.000 0.000 1.000 0.000 0.000 run tag=wave style=not-confident camera=90.0");
  Result<InputScript> back =
      parse_input_script(format_script_line(2.0f, input, "not-confident"), "styled");
  ASSERT_TRUE(back) << back.message();
  EXPECT_EQ(back->events()[0].style, "not-confident");

  // Values that round to zero print without a sign; a camera that rounds to zero is left out.
  ControllerInput tiny;
  tiny.left_stick = {-0.0001f, -0.0f};
  tiny.camera_yaw = -0.01f * kDegree;
  EXPECT_EQ(format_script_line(0.0f, tiny), "0.000 0.000 0.000 0.000 0.000");
}

TEST(InputScript, FormatAlwaysPrintsALineThatParses) {
  // Live input may hold anything: non-finite values count as 0 (input.hpp), a stick beyond
  // [-1, 1] is scaled back along its direction, a negative time prints as 0.
  ControllerInput wild;
  wild.left_stick = {1.5f, 0.75f};
  wild.right_stick = {kNaN, -3.0f};
  wild.camera_yaw = kInf;
  EXPECT_EQ(format_script_line(-2.0f, wild), "0.000 1.000 0.500 0.000 -1.000");
  EXPECT_EQ(format_script_line(kNaN, ControllerInput{}), "0.000 0.000 0.000 0.000 0.000");
  for (const std::string& line :
       {format_script_line(-2.0f, wild), format_script_line(kNaN, wild)}) {
    EXPECT_TRUE(parse_input_script(line, "live").ok()) << line;
  }
}

TEST(InputScript, FormattedLinesParseBackToThePrintedPrecision) {
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<float> stick(-1.0f, 1.0f);
  std::uniform_real_distribution<float> yaw(-10.0f, 10.0f);
  std::bernoulli_distribution coin(0.5);
  const char* const tags[] = {"", "wave", "raise-up-both-hands", "a.b:c+d_e"};
  std::vector<float> times;
  std::vector<ControllerInput> inputs;
  std::string text = "# recorded\n";
  float time = 0.0f;
  for (int i = 0; i < 500; ++i) {
    ControllerInput input;
    input.left_stick = {stick(rng), stick(rng)};
    input.right_stick = {stick(rng), stick(rng)};
    input.camera_yaw = yaw(rng);
    input.run = coin(rng);
    input.strafe = coin(rng);
    input.tag = tags[rng() % 4];
    time += 1.0f / 60.0f;
    times.push_back(time);
    inputs.push_back(input);
    text += format_script_line(time, input) + "\n";
  }
  const InputScript script = parse_ok(text);
  ASSERT_EQ(script.events().size(), inputs.size());
  for (size_t i = 0; i < inputs.size(); ++i) {
    const ScriptEvent& e = script.events()[i];
    const ControllerInput& in = inputs[i];
    EXPECT_NEAR(e.time, times[i], 0.0005f + 1e-6f) << i;
    EXPECT_NEAR(e.input.left_stick.x, in.left_stick.x, 0.0005f + 1e-6f) << i;
    EXPECT_NEAR(e.input.left_stick.y, in.left_stick.y, 0.0005f + 1e-6f) << i;
    EXPECT_NEAR(e.input.right_stick.x, in.right_stick.x, 0.0005f + 1e-6f) << i;
    EXPECT_NEAR(e.input.right_stick.y, in.right_stick.y, 0.0005f + 1e-6f) << i;
    EXPECT_NEAR(e.input.camera_yaw, in.camera_yaw, 0.05f * kDegree + 1e-6f) << i;
    EXPECT_EQ(e.input.run, in.run) << i;
    EXPECT_EQ(e.input.strafe, in.strafe) << i;
    EXPECT_EQ(e.input.tag, in.tag) << i;
    // Printing the parsed state again gives the same line: the format is a fixed point.
    EXPECT_EQ(format_script_line(e.time, e.input), format_script_line(times[i], in)) << i;
  }
}

// ---------------------------------------------------------------------------------------------
// Files.

TEST(InputScript, LoadReadsAFileAndNamesItInMessages) {
  const auto dir = test::scratch_dir();
  const auto good = dir / "good.txt";
  std::ofstream(good) << "# two lines\n0 0 1 0 0\n1.5 0 0 0 0 tag=wave\n";
  Result<InputScript> loaded = load_input_script(good);
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  ASSERT_EQ(loaded->events().size(), 2u);
  EXPECT_EQ(loaded->at(2.0f).tag, "wave");

  const auto bad = dir / "bad.txt";
  std::ofstream(bad) << "0 0 1 0 0\n1 0 0 0 0 jump\n";
  Result<InputScript> refused = load_input_script(bad);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.message(),
            bad.string() +
                ":2: expected run, strafe, tag=NAME, style=NAME or camera=DEGREES, found "
                "'jump'");
}

TEST(InputScript, LoadOfAMissingFileOrAFolderNamesThePath) {
  const auto dir = test::scratch_dir();
  const auto missing = dir / "no_such_script.txt";
  Result<InputScript> from_missing = load_input_script(missing);
  ASSERT_FALSE(from_missing.ok());
  EXPECT_EQ(from_missing.message(),
            missing.string() + ": cannot open the input script (No such file or directory)");

  Result<InputScript> from_folder = load_input_script(dir);
  ASSERT_FALSE(from_folder.ok());
  EXPECT_EQ(from_folder.message(),
            dir.string() + ": cannot read the input script (it is a folder)");
}

// ---------------------------------------------------------------------------------------------
// The scripts shipped in scripts/input/.

TEST(InputScript, EveryShippedScriptParsesAndLastsAtLeastTenSeconds) {
  const auto folder = std::filesystem::path(MM_SOURCE_DIR) / "scripts" / "input";
  ASSERT_TRUE(std::filesystem::is_directory(folder)) << folder;
  std::set<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() != ".txt") continue;
    names.insert(entry.path().filename().string());
    Result<InputScript> script = load_input_script(entry.path());
    ASSERT_TRUE(script.ok()) << script.message();
    EXPECT_GE(script->duration(), 10.0f) << entry.path();
    // A header says what the script exercises.
    std::ifstream in(entry.path());
    std::string first_line;
    std::getline(in, first_line);
    EXPECT_TRUE(first_line.starts_with("# ")) << entry.path();
  }
  for (const char* required : {"circle.txt", "zigzag.txt", "stop-and-go.txt", "strafe.txt",
                               "walk-run.txt", "camera-turns.txt", "random-long.txt"}) {
    EXPECT_TRUE(names.contains(required)) << required;
  }
  // One script requests a tag.
  Result<InputScript> wave = load_input_script(folder / "tag-wave.txt");
  ASSERT_TRUE(wave.ok()) << wave.message();
  EXPECT_TRUE(std::any_of(wave->events().begin(), wave->events().end(),
                          [](const ScriptEvent& e) { return e.tag == "wave"; }));
}

}  // namespace
}  // namespace mm
