#pragma once
// Clip tags: short words a search can filter by (gait, style, "action" clips, "mirrored"),
// derived from file names and from an optional manifest file.
//
// File names. A Bandai name "dataset-N_{content}_{style}_{id}" gives the tags
//   {content}                        e.g. "walk-turn-left", "wave-both-hands"
//   {style}                          e.g. "normal", "tired"
//   "locomotion" and the gait        when the content's first word is walk, run or dash
//                                    (e.g. "walk-back" -> "locomotion", "walk")
//   "action"                         for every other content (the standing wave-* and
//                                    raise-up-* gestures)
// A ReActIdle name "{person}_{genuine|acted}" (e.g. "003_genuine", or a segment of it such as
// "003_genuine_at68s") gives "idle", "reactidle"
// and "genuine" or "acted": real standing motion, which the controller plays when the stick is
// released (the builder then synthesizes no held-frame idle clip).
// Other names give no tags from the name.
//
// Manifest (mm build --tags FILE): a text file of lines "<glob> <tag> <tag> ...". '#' starts a
// comment; blank lines are ignored. The glob is matched against the whole clip name (the file
// stem, or the glTF animation name) with '*' (any run of characters) and '?' (one character);
// every matching line adds its tags. Tags are words of letters, digits and "_-.:+".
//
// The idle clip the builder synthesizes (idle.hpp) is named "idle": it gets the tag "idle" plus
// those of the manifest lines whose glob matches "idle". It is never mirrored.
//
// Mirrored clips get the tags their original would get (name and manifest, matched on the
// original name) with "left" and "right" swapped inside each tag ("walk-turn-left" becomes
// "walk-turn-right"), plus "mirrored".
//
// A database holds at most 64 distinct tags (one bit each in a clip's mask).
//
// Styles. A clip also has one style (how it moves: "tired", "proud"), kept apart from its tags
// in the database (ClipRange::style, Database::style_names) and requested by the controller as
// a cost, not a filter (docs/controller.md, Styles). It comes from
//   - a Bandai name's {style} (which also stays a tag, for `tag=` filters);
//   - a manifest word "style=NAME" on a matching line (NAME of the tag characters); the last
//     matching line with one wins over the name's. The style is added to the clip's tags too,
//     so that every style has a search filter bit.
// Idle clips (ReActIdle names, the synthesized idle) and other names have none, unless a
// manifest line gives one: a clip without a style serves every style. Mirrored clips keep
// their original's style.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "mm/runtime/result.hpp"

namespace mm {

// One manifest line: clips whose name matches `pattern` get `tags`.
struct TagRule {
  std::string pattern;            // glob over the clip name: '*' and '?'
  std::vector<std::string> tags;  // tags to add (a line may have only a style)
  std::string style;              // "style=NAME" on the line; empty: none
  int line = 0;                   // line in the manifest, for messages
};

// Most distinct tags a database can hold.
inline constexpr size_t kMaxTags = 64;

// True when the glob `pattern` ('*' any run, '?' one character) matches all of `text`.
bool glob_match(std::string_view pattern, std::string_view text);

// Parses manifest text; errors name "<path>:<line>" and what was expected.
Result<std::vector<TagRule>> parse_tag_manifest(std::string_view text,
                                                std::string_view path_for_messages);

// Reads and parses a manifest file.
Result<std::vector<TagRule>> load_tag_manifest(const std::filesystem::path& path);

// The tags a file name gives (see the top of this file), sorted, without duplicates.
std::vector<std::string> tags_from_name(std::string_view clip_name);

// All tags of a clip: from its name and the matching rules; for a mirrored clip pass the
// ORIGINAL clip's name and mirrored = true. Sorted, without duplicates.
std::vector<std::string> clip_tags(std::string_view clip_name, bool mirrored,
                                   const std::vector<TagRule>& rules);

// The style of a clip (see the top of this file): the last matching rule's style, else a Bandai
// name's {style}, else "" (none). For a mirrored clip pass the original's name.
std::string clip_style(std::string_view clip_name, const std::vector<TagRule>& rules);

// "left" <-> "right" (and "Left" <-> "Right") inside a tag.
std::string swap_left_right(std::string_view tag);

}  // namespace mm
