#pragma once
// The small system services the importers, the database file and the command line share:
// reading and writing a whole file, naming file types by extension, printing byte sizes, and
// hinting the kernel about large arrays. Cold paths only.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

#include "mm/runtime/result.hpp"

namespace mm {

// A whole file in memory. The buffer is not zero-filled before reading (the importers read
// hundreds of MB), and holds one extra '\0' after the last byte for parsers that want one.
struct FileContents {
  std::unique_ptr<char[]> data;
  size_t size = 0;

  std::string_view text() const { return {data.get(), size}; }
};

// Reads `path` in one go. Errors name the file and say why: "<path>: cannot open the <what> (No
// such file or directory)", "<path>: cannot read the <what> (it is a folder)". `what` names the
// file's role in messages ("input script").
Result<FileContents> read_whole_file(const std::filesystem::path& path,
                                     std::string_view what = "file");

// Replaces `path` with `bytes` in one go. Errors name the file and say why, as read_whole_file's
// do: "<path>: cannot write the <what> (Permission denied)", "... (it is a folder)".
Status write_whole_file(const std::filesystem::path& path, std::string_view bytes,
                        std::string_view what = "file");

// The extension in lower case, with its dot (".bvh"), or "" when there is none.
std::string lower_extension(const std::filesystem::path& path);

// True when the extension (ignoring case) is one of `extensions`, e.g. {".gltf", ".glb"}.
bool has_extension(const std::filesystem::path& path,
                   std::initializer_list<std::string_view> extensions);

// "512 B", "12.3 KB", "218.9 MB", "1.2 GB" (decimal units, one decimal).
std::string format_bytes(uint64_t bytes);

// Asks the kernel to back the whole 2 MiB pages inside [data, data + bytes) with transparent
// huge pages. Filling a fresh array takes a page fault per 4 KiB page, which costs more than
// writing the bytes; huge pages take 512 times fewer. Only a hint: where it fails (THP off,
// not Linux, a small block) nothing changes.
void advise_huge_pages(void* data, size_t bytes);

}  // namespace mm
