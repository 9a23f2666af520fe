// The glTF importer reads external buffers only from regular files inside the glTF file's
// folder whose size is the declared byteLength, under the cap; everything else is refused
// before it is opened, with a message naming the buffer, its uri and the reason.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <future>
#include <string>
#include <vector>

#include "base64.hpp"
#include "mm/offline/gltf.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

namespace fs = std::filesystem;

// The 32 bytes of the animation below: key times 0 and 1, then the root's translation keys
// (0, 0, 0) and (1, 2, 3).
std::vector<unsigned char> animation_bytes() {
  const float values[] = {0, 1, 0, 0, 0, 1, 2, 3};
  std::vector<unsigned char> bytes(sizeof values);
  std::memcpy(bytes.data(), values, sizeof values);
  return bytes;
}

// A one-joint skin animated by buffer 0, which is `uri` and claims `byte_length` bytes; with
// `image_uri`, also an image naming that file.
std::string gltf_text(const std::string& uri, uint64_t byte_length,
                      const std::string& image_uri = "") {
  std::string text = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],)";
  text += R"("nodes":[{"name":"root"}],"skins":[{"joints":[0]}],)";
  text += R"("buffers":[{"byteLength":)" + std::to_string(byte_length) + R"(,"uri":")" + uri +
          R"("}],)";
  text += R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":32}],)";
  text += R"("accessors":[
    {"bufferView":0,"byteOffset":0,"componentType":5126,"count":2,"type":"SCALAR","min":[0],"max":[1]},
    {"bufferView":0,"byteOffset":8,"componentType":5126,"count":2,"type":"VEC3"}],)";
  if (!image_uri.empty()) text += R"("images":[{"uri":")" + image_uri + R"("}],)";
  text += R"("animations":[{"name":"move","samplers":[{"input":0,"output":1}],
    "channels":[{"sampler":0,"target":{"node":0,"path":"translation"}}]}]})";
  return text;
}

void write_bytes(const fs::path& path, const std::vector<unsigned char>& bytes) {
  std::ofstream file(path, std::ios::binary);
  file.write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
}

fs::path write_gltf(const fs::path& path, const std::string& uri, uint64_t byte_length,
                    const std::string& image_uri = "") {
  const std::string text = gltf_text(uri, byte_length, image_uri);
  write_bytes(path, std::vector<unsigned char>(text.begin(), text.end()));
  return path;
}

void expect_refused(const Result<GltfAsset>& result, const fs::path& path,
                    const std::string& fragment) {
  ASSERT_FALSE(result.ok()) << "expected " << path << " to be refused (" << fragment << ")";
  EXPECT_NE(result.message().find(path.string() + ": buffer 0 (uri '"), std::string::npos)
      << result.message();
  EXPECT_NE(result.message().find(fragment), std::string::npos)
      << "message '" << result.message() << "' lacks '" << fragment << "'";
}

// The imported clip moved the root as animation_bytes() says: the buffer was read.
void expect_animation_read(const Result<GltfAsset>& asset) {
  ASSERT_TRUE(asset.ok()) << asset.message();
  ASSERT_EQ(asset->clips.size(), 1u);
  const Clip& clip = asset->clips[0];
  ASSERT_EQ(clip.frame_count, 2);
  EXPECT_EQ(clip.pose(1)[0].translation, glm::vec3(1.0f, 2.0f, 3.0f));
}

TEST(GltfConfinement, ReadsASiblingBinAndADataUri) {
  const fs::path dir = test::scratch_dir();
  write_bytes(dir / "clip data.bin", animation_bytes());
  // Percent-encoded, as glTF uris are: the file is "clip data.bin".
  expect_animation_read(
      load_gltf(write_gltf(dir / "sibling.gltf", "clip%20data.bin", 32), {.sample_rate = 1.0f}));
  fs::create_directories(dir / "sub");
  write_bytes(dir / "sub" / "below.bin", animation_bytes());
  expect_animation_read(
      load_gltf(write_gltf(dir / "below.gltf", "sub/../sub/below.bin", 32), {.sample_rate = 1.0f}));
  const std::string data_uri =
      "data:application/octet-stream;base64," + test::base64(animation_bytes());
  expect_animation_read(
      load_gltf(write_gltf(dir / "embedded.gltf", data_uri, 32), {.sample_rate = 1.0f}));
}

// load_gltf run on another thread; if it has not returned after 10 s (it opened the FIFO and
// waits for a writer), a writer opens and closes the FIFO so that the read ends, and the test
// fails.
Result<GltfAsset> load_without_blocking(const fs::path& path, const fs::path& fifo,
                                        const GltfImportOptions& options = {}) {
  auto loading = std::async(std::launch::async, [&] { return load_gltf(path, options); });
  if (loading.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
    const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (fd >= 0) ::close(fd);
    ADD_FAILURE() << "load_gltf opened the FIFO " << fifo << " and blocked";
  }
  return loading.get();
}

TEST(GltfConfinement, RefusesAFifoWithoutBlocking) {
  const fs::path dir = test::scratch_dir();
  const fs::path fifo = dir / "pipe.bin";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  const fs::path path = write_gltf(dir / "fifo.gltf", "pipe.bin", 32);
  expect_refused(load_without_blocking(path, fifo), path,
                 "buffer 0 (uri 'pipe.bin') is not a regular file (it is a FIFO)");
}

TEST(GltfConfinement, NeverOpensAnImageNamingAFifo) {
  const fs::path dir = test::scratch_dir();
  const fs::path fifo = dir / "texture.png";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  const std::string data_uri =
      "data:application/octet-stream;base64," + test::base64(animation_bytes());
  const fs::path path = write_gltf(dir / "textured.gltf", data_uri, 32, "texture.png");
  expect_animation_read(load_without_blocking(path, fifo, {.sample_rate = 1.0f}));
}

TEST(GltfConfinement, RefusesAFolder) {
  const fs::path dir = test::scratch_dir();
  fs::create_directories(dir / "folder.bin");
  const fs::path path = write_gltf(dir / "folder.gltf", "folder.bin", 32);
  expect_refused(load_gltf(path), path,
                 "buffer 0 (uri 'folder.bin') is not a regular file (it is a folder)");
}

TEST(GltfConfinement, RefusesDotDotOutOfTheFolder) {
  const fs::path dir = test::scratch_dir();
  write_bytes(dir / "outside.bin", animation_bytes());
  fs::create_directories(dir / "inner");
  const fs::path path = write_gltf(dir / "inner" / "climb.gltf", "../outside.bin", 32);
  expect_refused(load_gltf(path), path,
                 "buffer 0 (uri '../outside.bin') leaves the glTF file's folder through '..'");
  // A path that dips into a subfolder first climbs out all the same.
  fs::create_directories(dir / "inner" / "sub");
  const fs::path deeper = write_gltf(dir / "inner" / "deeper.gltf", "sub/../../outside.bin", 32);
  expect_refused(load_gltf(deeper), deeper, "leaves the glTF file's folder through '..'");
}

TEST(GltfConfinement, RefusesAnAbsolutePath) {
  const fs::path dir = test::scratch_dir();
  const fs::path bin = dir / "absolute.bin";
  write_bytes(bin, animation_bytes());
  const fs::path path = write_gltf(dir / "absolute.gltf", bin.string(), 32);
  expect_refused(load_gltf(path), path,
                 "buffer 0 (uri '" + bin.string() + "') is an absolute path; buffers may only " +
                     "name files inside the glTF file's folder, by a relative path");
}

TEST(GltfConfinement, RefusesASymlinkLeadingOutOfTheFolder) {
  const fs::path dir = test::scratch_dir();
  write_bytes(dir / "outside.bin", animation_bytes());
  fs::create_directories(dir / "inner");
  fs::create_symlink("../outside.bin", dir / "inner" / "link.bin");
  const fs::path path = write_gltf(dir / "inner" / "link.gltf", "link.bin", 32);
  expect_refused(load_gltf(path), path,
                 "buffer 0 (uri 'link.bin') resolves (through a symbolic link) to " +
                     fs::canonical(dir / "outside.bin").string() +
                     ", outside the glTF file's folder");
  // A link that stays inside the folder is followed.
  fs::create_symlink("../inner/data.bin", dir / "inner" / "inside_link.bin");
  write_bytes(dir / "inner" / "data.bin", animation_bytes());
  expect_animation_read(load_gltf(write_gltf(dir / "inner" / "ok.gltf", "inside_link.bin", 32),
                                  {.sample_rate = 1.0f}));
}

TEST(GltfConfinement, RefusesAFileAboveTheCap) {
  const fs::path dir = test::scratch_dir();
  // Sparse: no disk space and nothing to read, as the file is refused from its size.
  const uint64_t huge = kGltfMaxExternalBufferBytes + 1;
  { std::ofstream create(dir / "huge.bin"); }
  fs::resize_file(dir / "huge.bin", huge);
  const fs::path path = write_gltf(dir / "huge.gltf", "huge.bin", huge);
  expect_refused(load_gltf(path), path,
                 "buffer 0 (uri 'huge.bin') is " + std::to_string(huge) +
                     " bytes, above the cap of " + std::to_string(kGltfMaxExternalBufferBytes) +
                     " bytes on external buffers");
}

TEST(GltfConfinement, RefusesFilesAddingUpToMoreThanTheCap) {
  const fs::path dir = test::scratch_dir();
  // Two sparse files, each under the cap, together above it.
  const uint64_t half = kGltfMaxExternalBufferBytes / 2 + 1;
  for (const char* name : {"first.bin", "second.bin"}) {
    { std::ofstream create(dir / name); }
    fs::resize_file(dir / name, half);
  }
  std::string text = gltf_text("first.bin", half);
  const std::string second = R"({"byteLength":)" + std::to_string(half) + R"(,"uri":"second.bin"})";
  const size_t buffers_end = text.find("}],", text.find(R"("buffers")")) + 1;
  text.insert(buffers_end, "," + second);
  const fs::path path = dir / "two.gltf";
  write_bytes(path, std::vector<unsigned char>(text.begin(), text.end()));
  const Result<GltfAsset> asset = load_gltf(path);
  ASSERT_FALSE(asset.ok());
  EXPECT_NE(asset.message().find(path.string() + ": buffer 1 (uri 'second.bin') brings the " +
                                 "external buffers to " + std::to_string(2 * half) +
                                 " bytes, above the cap of " +
                                 std::to_string(kGltfMaxExternalBufferBytes) + " bytes"),
            std::string::npos)
      << asset.message();
}

TEST(GltfConfinement, RefusesASizeThatIsNotTheByteLength) {
  const fs::path dir = test::scratch_dir();
  write_bytes(dir / "data.bin", animation_bytes());
  const fs::path path = write_gltf(dir / "mismatch.gltf", "data.bin", 28);
  expect_refused(load_gltf(path), path,
                 "buffer 0 (uri 'data.bin') is 32 bytes but its byteLength says 28");
  const fs::path missing = write_gltf(dir / "missing.gltf", "absent.bin", 32);
  expect_refused(load_gltf(missing), missing,
                 "buffer 0 (uri 'absent.bin') cannot be opened (No such file or directory)");
}

TEST(GltfConfinement, RefusesEveryFileWhenParsingFromMemory) {
  const fs::path dir = test::scratch_dir();
  write_bytes(dir / "data.bin", animation_bytes());
  const std::string text = gltf_text("data.bin", 32);
  const fs::path name = dir / "memory.gltf";
  const auto bytes = std::span(reinterpret_cast<const unsigned char*>(text.data()), text.size());
  expect_refused(parse_gltf(bytes, name, {.allow_external_files = false}), name,
                 "buffer 0 (uri 'data.bin') names a file, which is refused for glTF parsed from "
                 "memory");
  // The same bytes, allowed files, read the sibling: only the option refused it.
  expect_animation_read(parse_gltf(bytes, name, {.sample_rate = 1.0f}));
}

}  // namespace
}  // namespace mm
