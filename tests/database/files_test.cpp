// The shared file services: whole-file reads and writes (contents and every failure by its
// message), file types by extension, byte sizes for people, and the huge-page hint's safety.

#include "mm/database/files.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace mm {
namespace {

using test::scratch_dir;

std::filesystem::path write_file(const std::string& name, const std::string& bytes) {
  const std::filesystem::path path = scratch_dir() / name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

TEST(ReadWholeFile, ReturnsEveryByteIncludingNulsAndEndsWithATerminator) {
  std::string bytes = "HIERARCHY\nROOT Hips\n";
  bytes.push_back('\0');
  bytes += "after the nul";
  const auto path = write_file("files_test_bytes.bin", bytes);
  auto contents = read_whole_file(path);
  ASSERT_TRUE(contents) << contents.message();
  EXPECT_EQ(contents->size, bytes.size());
  EXPECT_EQ(std::string(contents->text()), bytes);
  EXPECT_EQ(contents->data[contents->size], '\0');
}

TEST(ReadWholeFile, AnEmptyFileIsEmptyNotAnError) {
  auto contents = read_whole_file(write_file("files_test_empty.bin", ""));
  ASSERT_TRUE(contents) << contents.message();
  EXPECT_EQ(contents->size, 0u);
  EXPECT_EQ(contents->text(), "");
}

TEST(ReadWholeFile, AFileLargerThanTheFirstGuessIsReadWhole) {
  // 3 MB crosses any small first buffer and a huge-page boundary.
  std::string bytes(3'000'000, 'x');
  for (size_t i = 0; i < bytes.size(); i += 997) bytes[i] = static_cast<char>('a' + i % 26);
  auto contents = read_whole_file(write_file("files_test_large.bin", bytes));
  ASSERT_TRUE(contents) << contents.message();
  EXPECT_EQ(std::string(contents->text()), bytes);
}

TEST(ReadWholeFile, AMissingFileIsNamedWithItsRoleAndTheSystemReason) {
  const auto path = scratch_dir() / "files_test_no_such_file.txt";
  auto contents = read_whole_file(path, "input script");
  ASSERT_FALSE(contents);
  EXPECT_EQ(contents.message(),
            path.string() + ": cannot open the input script (No such file or directory)");
}

TEST(ReadWholeFile, AFolderIsRefusedByName) {
  auto contents = read_whole_file(scratch_dir(), "tag manifest");
  ASSERT_FALSE(contents);
  EXPECT_EQ(contents.message(),
            scratch_dir().string() + ": cannot read the tag manifest (it is a folder)");
}

TEST(WriteWholeFile, ReplacesTheFileWithEveryByte) {
  std::string bytes = "MOTION\n";
  bytes.push_back('\0');
  bytes += "after the nul";
  const auto path = write_file("files_test_written.bin", "an older, longer content to replace");
  ASSERT_TRUE(write_whole_file(path, bytes));
  auto contents = read_whole_file(path);
  ASSERT_TRUE(contents) << contents.message();
  EXPECT_EQ(std::string(contents->text()), bytes);
}

TEST(WriteWholeFile, FailuresNameTheFileItsRoleAndTheReason) {
  const auto missing = scratch_dir() / "no_such_folder" / "out.bvh";
  Status status = write_whole_file(missing, "x", "BVH file");
  ASSERT_FALSE(status);
  EXPECT_EQ(status.message(),
            missing.string() + ": cannot write the BVH file (No such file or directory)");
  status = write_whole_file(scratch_dir(), "x", "BVH file");
  ASSERT_FALSE(status);
  EXPECT_EQ(status.message(),
            scratch_dir().string() + ": cannot write the BVH file (it is a folder)");
}

TEST(Extensions, AreComparedWithoutCase) {
  EXPECT_EQ(lower_extension("clips/Walk.BVH"), ".bvh");
  EXPECT_EQ(lower_extension("clips/no_extension"), "");
  EXPECT_EQ(lower_extension("archive.tar.GZ"), ".gz");
  EXPECT_TRUE(has_extension("a/b.GLB", {".gltf", ".glb"}));
  EXPECT_TRUE(has_extension("a/b.gltf", {".gltf", ".glb"}));
  EXPECT_FALSE(has_extension("a/b.bvh", {".gltf", ".glb"}));
  EXPECT_FALSE(has_extension("a/glb", {".glb"}));
}

TEST(FormatBytes, UsesDecimalUnitsWithOneDecimal) {
  EXPECT_EQ(format_bytes(0), "0 B");
  EXPECT_EQ(format_bytes(999), "999 B");
  EXPECT_EQ(format_bytes(1000), "1.0 KB");
  EXPECT_EQ(format_bytes(12'345), "12.3 KB");
  EXPECT_EQ(format_bytes(218'900'000), "218.9 MB");
  EXPECT_EQ(format_bytes(1'250'000'000), "1.2 GB");
}

TEST(AdviseHugePages, LeavesTheBytesAsTheyWereForSmallAndLargeBlocks) {
  // Only a hint: whatever the kernel does, the memory keeps its contents.
  for (size_t n : {size_t{0}, size_t{100}, size_t{9} << 20}) {
    std::vector<unsigned char> block(n);
    for (size_t i = 0; i < n; ++i) block[i] = static_cast<unsigned char>(i * 31);
    advise_huge_pages(block.data(), block.size());
    for (size_t i = 0; i < n; i += 4093) {
      ASSERT_EQ(block[i], static_cast<unsigned char>(i * 31)) << n;
    }
  }
}

}  // namespace
}  // namespace mm
