// The level reader (mm/world/level.hpp): glTF files made here, in memory (JSON with its buffer
// as a data: URI, or a GLB), read into triangles with the node transforms applied; every refusal
// checked by its message, which names the file and what is wrong. And Level::validate.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "base64.hpp"
#include "mm/world/level.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

namespace fs = std::filesystem;

constexpr const char* kName = "level.gltf";

// A glTF file under construction: one buffer (embedded as a data: URI, or a GLB's binary
// chunk), one buffer view per accessor, and JSON written by hand so that tests can break any
// part of it.
class GltfText {
 public:
  // A FLOAT VEC3 accessor over `values` (three per vertex).
  int positions(const std::vector<float>& values) {
    return add(values.data(), values.size() * sizeof(float), values.size() / 3,
               R"("componentType":5126,"type":"VEC3")");
  }
  // An UNSIGNED_INT SCALAR accessor.
  int indices(const std::vector<uint32_t>& values) {
    return add(values.data(), values.size() * sizeof(uint32_t), values.size(),
               R"("componentType":5125,"type":"SCALAR")");
  }
  // An UNSIGNED_BYTE SCALAR accessor (a cheap way to declare many indices).
  int byte_indices(const std::vector<uint8_t>& values) {
    return add(values.data(), values.size(), values.size(),
               R"("componentType":5121,"type":"SCALAR")");
  }
  // Any accessor, as JSON ("bufferView" and all).
  int accessor(const std::string& json) {
    accessors_.push_back(json);
    return static_cast<int>(accessors_.size() - 1);
  }
  // A mesh of the given primitives (JSON objects), named `name`.
  int mesh(const std::string& name, const std::vector<std::string>& primitives) {
    std::string json = R"({"name":")" + name + R"(","primitives":[)";
    for (size_t i = 0; i < primitives.size(); ++i) json += (i ? "," : "") + primitives[i];
    meshes_.push_back(json + "]}");
    return static_cast<int>(meshes_.size() - 1);
  }
  // A node (its JSON object's members, e.g. "\"mesh\":0,\"translation\":[1,2,3]").
  int node(const std::string& members) {
    nodes_.push_back("{" + members + "}");
    return static_cast<int>(nodes_.size() - 1);
  }
  // The top-level members after the asset, e.g. the scenes; by default one scene of node 0.
  std::string extra = R"("scene":0,"scenes":[{"nodes":[0]}])";

  std::string json(bool embed_buffer = true) const {
    std::string text = R"({"asset":{"version":"2.0"},)" + extra;
    if (!bin_.empty()) {
      text += R"(,"buffers":[{"byteLength":)" + std::to_string(bin_.size());
      if (embed_buffer) {
        text += R"(,"uri":"data:application/octet-stream;base64,)" + test::base64(bin_) + "\"";
      }
      text += "}]";
    }
    text += list("bufferViews", views_) + list("accessors", accessors_) + list("meshes", meshes_) +
            list("nodes", nodes_) + "}";
    return text;
  }

  std::vector<unsigned char> text_bytes() const {
    const std::string text = json();
    return {text.begin(), text.end()};
  }

  // The same as a GLB: the JSON chunk, then the buffer as the binary chunk.
  std::vector<unsigned char> glb() const {
    std::string text = json(false);
    while (text.size() % 4 != 0) text += ' ';
    std::vector<unsigned char> bin = bin_;
    while (bin.size() % 4 != 0) bin.push_back(0);
    std::vector<unsigned char> out;
    auto u32 = [&](uint32_t v) {
      for (int k = 0; k < 4; ++k) out.push_back(static_cast<unsigned char>(v >> (8 * k)));
    };
    out.insert(out.end(), {'g', 'l', 'T', 'F'});
    u32(2);
    u32(static_cast<uint32_t>(12 + 8 + text.size() + 8 + bin.size()));
    u32(static_cast<uint32_t>(text.size()));
    u32(0x4E4F534Au);
    out.insert(out.end(), text.begin(), text.end());
    u32(static_cast<uint32_t>(bin.size()));
    u32(0x004E4942u);
    out.insert(out.end(), bin.begin(), bin.end());
    return out;
  }

  std::vector<unsigned char> bin_;

 private:
  int add(const void* data, size_t bytes, size_t count, const std::string& type) {
    while (bin_.size() % 4 != 0) bin_.push_back(0);
    views_.push_back(R"({"buffer":0,"byteOffset":)" + std::to_string(bin_.size()) +
                     R"(,"byteLength":)" + std::to_string(bytes) + "}");
    const auto* p = static_cast<const unsigned char*>(data);
    bin_.insert(bin_.end(), p, p + bytes);
    return accessor(R"({"bufferView":)" + std::to_string(views_.size() - 1) + R"(,"count":)" +
                    std::to_string(count) + "," + type + "}");
  }

  static std::string list(const std::string& name, const std::vector<std::string>& items) {
    if (items.empty()) return "";
    std::string text = ",\"" + name + "\":[";
    for (size_t i = 0; i < items.size(); ++i) text += (i ? "," : "") + items[i];
    return text + "]";
  }

  std::vector<std::string> views_;
  std::vector<std::string> accessors_;
  std::vector<std::string> meshes_;
  std::vector<std::string> nodes_;
};

std::string primitive(int positions, int indices = -1, int mode = -1) {
  std::string json = R"({"attributes":{"POSITION":)" + std::to_string(positions) + "}";
  if (indices >= 0) json += R"(,"indices":)" + std::to_string(indices);
  if (mode >= 0) json += R"(,"mode":)" + std::to_string(mode);
  return json + "}";
}

// A 2 by 2 m square on the ground (y = 0), x and z in [0, 2], as two triangles.
const std::vector<float> kSquare = {0, 0, 0, 2, 0, 0, 2, 0, 2, 0, 0, 2};
const std::vector<uint32_t> kSquareIndices = {0, 2, 1, 0, 3, 2};

// One node "floor" holding mesh "tiles" (the square), with `node_members` added to the node.
GltfText square_file(const std::string& node_members = "") {
  GltfText file;
  const int p = file.positions(kSquare);
  const int i = file.indices(kSquareIndices);
  file.mesh("tiles", {primitive(p, i)});
  file.node(R"("name":"floor","mesh":0)" + (node_members.empty() ? "" : "," + node_members));
  return file;
}

Result<Level> parse(const std::vector<unsigned char>& bytes, const fs::path& name = kName) {
  return parse_level(bytes, name, {.allow_external_files = false});
}

// The refusal must start with the file's name and contain `fragment`.
void expect_refused(const Result<Level>& result, const std::string& fragment,
                    const fs::path& name = kName) {
  ASSERT_FALSE(result.ok()) << "expected a refusal containing '" << fragment << "'";
  EXPECT_EQ(result.message().rfind(name.string() + ": ", 0), 0u) << result.message();
  EXPECT_NE(result.message().find(fragment), std::string::npos)
      << "message '" << result.message() << "' lacks '" << fragment << "'";
}

// The world position of a level's vertex.
glm::dvec3 world(const Level& level, size_t vertex) {
  return level.origin + glm::dvec3(level.positions[vertex]);
}

// ---------------------------------------------------------------------------------------------
// What is read

TEST(LevelFile, ReadsTrianglesWithTheNodeHierarchysTransforms) {
  // The square under a parent moved by (10, 1, 0), itself turned 90° about +Y and scaled by 2:
  // local (x, 0, z) goes to (10 + 2z, 1, -2x).
  GltfText file;
  const int p = file.positions(kSquare);
  const int i = file.indices(kSquareIndices);
  file.mesh("tiles", {primitive(p, i)});
  file.node(R"("name":"parent","translation":[10,1,0],"children":[1])");
  const double s = std::sqrt(0.5);
  file.node(R"("name":"floor","mesh":0,"scale":[2,2,2],"rotation":[0,)" + std::to_string(s) +
            ",0," + std::to_string(s) + "]");
  for (const auto& bytes : {file.text_bytes(), file.glb()}) {
    const Result<Level> level = parse(bytes, bytes[0] == 'g' ? "level.glb" : kName);
    ASSERT_TRUE(level.ok()) << level.message();
    ASSERT_EQ(level->triangle_count(), 2u);
    ASSERT_EQ(level->positions.size(), 4u);
    // The origin is the whole metre nearest the bounds' centre: x in [10, 14], z in [-4, 0].
    EXPECT_EQ(level->origin, glm::dvec3(12.0, 1.0, -2.0));
    for (size_t v = 0; v < 4; ++v) {
      const glm::dvec3 local(kSquare[v * 3], kSquare[v * 3 + 1], kSquare[v * 3 + 2]);
      const glm::dvec3 expected(10.0 + 2.0 * local.z, 1.0, -2.0 * local.x);
      const glm::dvec3 got = world(*level, v);
      EXPECT_NEAR(got.x, expected.x, 1e-5) << "vertex " << v;
      EXPECT_NEAR(got.y, expected.y, 1e-5) << "vertex " << v;
      EXPECT_NEAR(got.z, expected.z, 1e-5) << "vertex " << v;
    }
    EXPECT_EQ(level->indices, kSquareIndices);
  }
}

TEST(LevelFile, AMatrixPlacesANodeAsItsTrsWould) {
  // Column-major: a translation by (3, 0, 4).
  const Result<Level> level =
      parse(square_file(R"("matrix":[1,0,0,0, 0,1,0,0, 0,0,1,0, 3,0,4,1])").text_bytes());
  ASSERT_TRUE(level.ok()) << level.message();
  EXPECT_EQ(world(*level, 2), glm::dvec3(5.0, 0.0, 6.0));
}

TEST(LevelFile, AMeshUsedByTwoNodesIsPlacedTwice) {
  GltfText file = square_file();
  file.node(R"("name":"again","mesh":0,"translation":[0,0,5])");
  file.extra = R"("scene":0,"scenes":[{"nodes":[0,1]}])";
  const Result<Level> level = parse(file.text_bytes());
  ASSERT_TRUE(level.ok()) << level.message();
  ASSERT_EQ(level->triangle_count(), 4u);
  EXPECT_EQ(world(*level, 6), glm::dvec3(2.0, 0.0, 7.0));  // the second copy's vertex 2
  EXPECT_EQ(level->indices[9], 4u);                        // its indices start at its vertices
}

TEST(LevelFile, UnindexedPrimitivesTakeTheirVerticesThreeByThree) {
  GltfText file;
  file.positions({0, 0, 0, 1, 0, 0, 0, 0, 1, 5, 0, 5, 6, 0, 5, 5, 0, 6});
  file.mesh("loose", {primitive(0)});
  file.node(R"("mesh":0)");
  const Result<Level> level = parse(file.text_bytes());
  ASSERT_TRUE(level.ok()) << level.message();
  EXPECT_EQ(level->indices, (std::vector<uint32_t>{0, 1, 2, 3, 4, 5}));
}

TEST(LevelFile, PointsAndLinesAreSkipped) {
  GltfText file = square_file();
  const int points = file.positions({0, 5, 0, 1, 5, 0});
  file.mesh("markers", {primitive(points, -1, 0), primitive(points, -1, 1),
                        primitive(points, -1, 2), primitive(points, -1, 3)});
  file.node(R"("mesh":1)");
  file.extra = R"("scene":0,"scenes":[{"nodes":[0,1]}])";
  const Result<Level> level = parse(file.text_bytes());
  ASSERT_TRUE(level.ok()) << level.message();
  EXPECT_EQ(level->triangle_count(), 2u);
  EXPECT_EQ(level->positions.size(), 4u);
}

TEST(LevelFile, OnlyTheDefaultSceneIsRead) {
  GltfText file = square_file();
  file.node(R"("name":"elsewhere","mesh":0,"translation":[50,0,0])");
  file.extra = R"("scene":1,"scenes":[{"nodes":[0]},{"nodes":[1]}])";
  const Result<Level> level = parse(file.text_bytes());
  ASSERT_TRUE(level.ok()) << level.message();
  EXPECT_EQ(level->triangle_count(), 2u);
  EXPECT_GE(world(*level, 0).x, 50.0);
}

TEST(LevelFile, WithoutScenesEveryRootNodeIsRead) {
  GltfText file = square_file(R"("children":[1])");
  file.node(R"("mesh":0,"translation":[0,0,5])");
  file.node(R"("mesh":0,"translation":[0,0,10])");
  file.extra = R"("asset2":{})";
  const Result<Level> level = parse(file.text_bytes());
  ASSERT_TRUE(level.ok()) << level.message();
  EXPECT_EQ(level->triangle_count(), 6u);
}

TEST(LevelFile, ALevelFarOutKeepsItsVerticesExact) {
  // 100 km out on x and z: a float would hold only 8 mm steps there; relative to the level's
  // origin (the whole metre at its centre) the vertices keep the file's own floats exactly.
  const Result<Level> level =
      parse(square_file(R"("translation":[99997.25,0,-99999.25])").text_bytes());
  ASSERT_TRUE(level.ok()) << level.message();
  EXPECT_EQ(level->origin, glm::dvec3(99998.0, 0.0, -99998.0));
  EXPECT_EQ(level->positions[0], glm::vec3(-0.75f, 0.0f, -1.25f));
  EXPECT_EQ(level->positions[2], glm::vec3(1.25f, 0.0f, 0.75f));
  EXPECT_EQ(world(*level, 2), glm::dvec3(99999.25, 0.0, -99997.25));
}

TEST(LevelFile, ReadsABufferFileBesideTheLevel) {
  const fs::path dir = test::scratch_dir();
  GltfText file = square_file();
  {
    std::ofstream bin(dir / "level data.bin", std::ios::binary);
    bin.write(reinterpret_cast<const char*>(file.bin_.data()),
              static_cast<std::streamsize>(file.bin_.size()));
  }
  std::string text = file.json(false);
  const std::string length = R"("byteLength":)" + std::to_string(file.bin_.size());
  text.replace(text.find(length), length.size(), length + R"(,"uri":"level%20data.bin")");
  std::ofstream(dir / "level.gltf") << text;
  const Result<Level> level = load_level(dir / "level.gltf");
  ASSERT_TRUE(level.ok()) << level.message();
  EXPECT_EQ(level->triangle_count(), 2u);
}

TEST(LevelFile, ReadsWhatASceneHoldsBesidesMeshes) {
  // Materials, cameras and an image naming a file that does not exist: none of it is read.
  GltfText file = square_file();
  file.extra += R"(,"materials":[{"name":"grass"}],"cameras":[{"type":"perspective","perspective":)"
                R"({"yfov":1,"znear":0.1}}],"images":[{"uri":"missing.png"}])";
  const Result<Level> level = parse(file.text_bytes());
  ASSERT_TRUE(level.ok()) << level.message();
  EXPECT_EQ(level->triangle_count(), 2u);
}

// ---------------------------------------------------------------------------------------------
// What is refused

TEST(LevelFile, RefusesWhatIsNotGltf) {
  const std::string text = "solid cube\nfacet normal 0 0 1\n";
  expect_refused(parse({text.begin(), text.end()}), "not a valid glTF 2.0 file");
  expect_refused(parse({}), "not a valid glTF 2.0 file");
  expect_refused(parse(square_file().text_bytes(), "level.glb"),
                 "not a binary glTF file (it does not start with the \"glTF\" magic)", "level.glb");
  std::vector<unsigned char> glb = square_file().glb();
  glb.resize(glb.size() - 8);
  expect_refused(parse(glb, "level.glb"), "binary glTF (GLB) header says the file has",
                 "level.glb");
  glb = square_file().glb();
  glb[4] = 1;
  expect_refused(parse(glb, "level.glb"), "binary glTF (GLB) version 1 is not supported",
                 "level.glb");
}

TEST(LevelFile, RefusesAFileWithoutTriangles) {
  GltfText empty;
  empty.node(R"("name":"lonely")");
  expect_refused(parse(empty.text_bytes()), "has no triangles");
  GltfText lines;
  lines.positions({0, 0, 0, 1, 0, 0});
  lines.mesh("line", {primitive(0, -1, 1)});
  lines.node(R"("mesh":0)");
  expect_refused(parse(lines.text_bytes()), "has no triangles");
}

TEST(LevelFile, RefusesNonFiniteCoordinates) {
  GltfText file;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  file.positions({0, 0, 0, nan, 0, 0, 0, 0, 1});
  file.mesh("broken", {primitive(0)});
  file.node(R"("name":"floor","mesh":0)");
  expect_refused(parse(file.text_bytes()),
                 "node 0 'floor', mesh 0 'broken', primitive 0: POSITION element 1 is not finite");
  // Finite in the file, infinite once scaled: 10 * 1e308.
  GltfText scaled;
  scaled.positions({10, 0, 0, 11, 0, 0, 10, 0, 1});
  scaled.mesh("far", {primitive(0)});
  scaled.node(R"("mesh":0,"scale":[1e308,1,1])");
  expect_refused(parse(scaled.text_bytes()),
                 "node 0, mesh 0 'far', primitive 0: vertex 0 is not finite once the node "
                 "transforms are applied");
}

TEST(LevelFile, RefusesCoordinatesBeyondAHundredKilometres) {
  expect_refused(parse(square_file(R"("translation":[0,0,99999])").text_bytes()),
                 "node 0 'floor', mesh 0 'tiles', primitive 0: vertex 2 lies at (2, 0, 100001) "
                 "in the world, beyond ±100000 m");
  EXPECT_TRUE(parse(square_file(R"("translation":[0,0,99998])").text_bytes()).ok());
}

TEST(LevelFile, RefusesADegenerateTriangleByNodeMeshPrimitiveAndIndex) {
  GltfText file;
  const int p = file.positions({0, 0, 0, 2, 0, 0, 2, 0, 2, 1, 0, 1});
  const int good = file.indices({0, 2, 1});
  // Triangle 1 is 0, 2, 3: three points on the diagonal.
  const int bad = file.indices({0, 2, 1, 0, 2, 3});
  file.mesh("tiles", {primitive(p, good)});
  file.mesh("more", {primitive(p, good), primitive(p, bad)});
  file.node(R"("name":"floor","mesh":1)");
  expect_refused(parse(file.text_bytes()),
                 "node 0 'floor', mesh 1 'more', primitive 1, triangle 1 is degenerate: zero area");
  // A node scaled to nothing makes every triangle of its mesh degenerate.
  expect_refused(parse(square_file(R"("scale":[1,1,0])").text_bytes()),
                 "node 0 'floor', mesh 0 'tiles', primitive 0, triangle 0 is degenerate: zero "
                 "area");
  // A sliver: 100 m long, 0.5 mm high.
  GltfText sliver;
  sliver.positions({0, 0, 0, 100, 0, 0, 50, 0, 0.0005f});
  sliver.mesh("sliver", {primitive(0)});
  sliver.node(R"("mesh":0)");
  expect_refused(parse(sliver.text_bytes()),
                 "node 0, mesh 0 'sliver', primitive 0, triangle 0 is degenerate: a sliver: its "
                 "height is 5e-06 of its longest side (at least 1e-05)");
}

TEST(LevelFile, CountsTrianglesBeforeReadingThem) {
  // 60 000 triangles (UNSIGNED_BYTE indices: 180 kB) placed by 84 nodes: 5 040 000, over the
  // limit. Refused from the counts alone (the indices, all zero, are never read: they would make
  // degenerate triangles).
  GltfText file;
  file.positions({0, 0, 0, 1, 0, 0, 0, 0, 1});
  file.byte_indices(std::vector<uint8_t>(180'000, 0));
  file.mesh("many", {primitive(0, 1)});
  std::string roots;
  for (int n = 0; n < 84; ++n) {
    file.node(R"("mesh":0)");
    roots += (n ? "," : "") + std::to_string(n);
  }
  file.extra = R"("scene":0,"scenes":[{"nodes":[)" + roots + "]}]";
  const auto start = std::chrono::steady_clock::now();
  expect_refused(parse(file.text_bytes()),
                 "declares more than 5000000 triangles (the most a level may have; counted from "
                 "the accessors, once per node using a mesh, up to node 83, mesh 0 'many', "
                 "primitive 0)");
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
}

TEST(LevelFile, CountsVerticesBeforeReadingThem) {
  // 200 000 vertices (2.4 MB) used by one triangle, placed by 76 nodes: 15.2 million vertices.
  GltfText file;
  file.positions(std::vector<float>(600'000, 0.0f));
  file.indices({0, 1, 2});
  file.mesh("cloud", {primitive(0, 1)});
  std::string roots;
  for (int n = 0; n < 76; ++n) {
    file.node(R"("mesh":0)");
    roots += (n ? "," : "") + std::to_string(n);
  }
  file.extra = R"("scene":0,"scenes":[{"nodes":[)" + roots + "]}]";
  expect_refused(parse(file.text_bytes()), "declares more than 15000000 vertices");
}

TEST(LevelFile, RefusesCountsTheBytesDoNotHold) {
  // A billion triangles declared over a buffer of 36 bytes: refused before anything is read.
  GltfText file = square_file();
  file.accessor(R"({"bufferView":1,"count":3000000000,"componentType":5125,"type":"SCALAR"})");
  file.mesh("huge", {primitive(0, 2)});
  file.node(R"("name":"big","mesh":1)");
  file.extra = R"("scene":0,"scenes":[{"nodes":[1]}])";
  expect_refused(parse(file.text_bytes()),
                 "node 1 'big', mesh 1 'huge', primitive 0: indices (accessor 2): 3000000000 "
                 "elements of 4 bytes (stride 4) from byte offset 0 do not fit in buffer view 1 "
                 "(24 bytes)");
}

TEST(LevelFile, RefusesStripsFansAndUnknownModes) {
  for (const auto& [mode, name] : {std::pair{5, "5 (TRIANGLE_STRIP)"},
                                   std::pair{6, "6 (TRIANGLE_FAN)"}, std::pair{9, "9 (unknown)"}}) {
    GltfText file;
    file.positions(kSquare);
    file.mesh("strip", {primitive(0, -1, mode)});
    file.node(R"("mesh":0)");
    expect_refused(parse(file.text_bytes()),
                   std::string("node 0, mesh 0 'strip', primitive 0 has mode ") + name +
                       "; only TRIANGLES (4) is read");
  }
}

TEST(LevelFile, RefusesBadPrimitives) {
  auto refused = [](const std::string& primitive_json, const std::string& fragment,
                    const std::string& accessor = "") {
    GltfText file;
    file.positions(kSquare);
    file.indices({0, 2, 1, 0});
    if (!accessor.empty()) file.accessor(accessor);
    file.mesh("bad", {primitive_json});
    file.node(R"("mesh":0)");
    expect_refused(parse(file.text_bytes()), "node 0, mesh 0 'bad', primitive 0" + fragment);
  };
  refused(R"({"attributes":{"NORMAL":0}})", " has no POSITION attribute");
  refused(primitive(0, 1), " has 4 indices, not a multiple of 3");
  refused(primitive(0), " has 4 vertices and no indices, not a multiple of 3");
  refused(primitive(7), ": POSITION is accessor 7, out of range (the file has 2 accessors)");
  refused(primitive(2), ": POSITION (accessor 2) has type VEC2, expected VEC3",
          R"({"bufferView":0,"count":6,"componentType":5126,"type":"VEC2"})");
  refused(primitive(2),
          ": POSITION (accessor 2) has component type SHORT (normalized), expected FLOAT",
          R"({"bufferView":0,"count":4,"componentType":5122,"normalized":true,"type":"VEC3"})");
  refused(primitive(0, 2),
          ": indices (accessor 2) has component type FLOAT, expected "
          "UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT",
          R"({"bufferView":1,"count":3,"componentType":5126,"type":"SCALAR"})");
  refused(primitive(2), ": POSITION (accessor 2) has no buffer view (all zeros",
          R"({"count":3,"componentType":5126,"type":"VEC3"})");
  refused(primitive(2), ": POSITION (accessor 2) is sparse, which is not supported",
          R"({"bufferView":0,"count":4,"componentType":5126,"type":"VEC3","sparse":{"count":1,)"
          R"("indices":{"bufferView":1,"componentType":5125},"values":{"bufferView":0}}})");
  refused(primitive(2), ": POSITION (accessor 2) refers to buffer view 9, out of range",
          R"({"bufferView":9,"count":4,"componentType":5126,"type":"VEC3"})");

  // An index naming a vertex the primitive does not have.
  GltfText file;
  file.positions({0, 0, 0, 1, 0, 0, 0, 0, 1});
  file.indices({0, 1, 7});
  file.mesh("bad", {primitive(0, 1)});
  file.node(R"("mesh":0)");
  expect_refused(parse(file.text_bytes()),
                 "node 0, mesh 0 'bad', primitive 0: index 2 is vertex 7, but POSITION has 3 "
                 "vertices");
}

TEST(LevelFile, RefusesRequiredExtensions) {
  GltfText file = square_file();
  file.extra += R"(,"extensionsUsed":["KHR_draco_mesh_compression"],)"
                R"("extensionsRequired":["KHR_draco_mesh_compression"])";
  expect_refused(parse(file.text_bytes()),
                 "requires the extensions KHR_draco_mesh_compression, which the level reader "
                 "does not read");
}

TEST(LevelFile, RefusesANodeHierarchyThatIsNotATree) {
  GltfText two_parents = square_file(R"("children":[2])");
  two_parents.node(R"("children":[2])");
  two_parents.node(R"("name":"child")");
  expect_refused(parse(two_parents.text_bytes()),
                 "node 2 'child' has more than one parent (or is its own child)");

  GltfText cycle = square_file(R"("children":[1])");
  cycle.node(R"("name":"loop","children":[0])");
  expect_refused(parse(cycle.text_bytes()),
                 "scene 0 reaches node 0 'floor' twice (it is listed twice, or is both a root "
                 "and a child)");

  GltfText listed_twice = square_file();
  listed_twice.extra = R"("scene":0,"scenes":[{"nodes":[0,0]}])";
  expect_refused(parse(listed_twice.text_bytes()), "scene 0 reaches node 0 'floor' twice");

  expect_refused(parse(square_file(R"("children":[5])").text_bytes()),
                 "node 0 'floor' lists child 5, out of range (the file has 1 nodes)");
  GltfText bad_root = square_file();
  bad_root.extra = R"("scene":0,"scenes":[{"nodes":[3]}])";
  expect_refused(parse(bad_root.text_bytes()),
                 "scene 0 lists node 3, out of range (the file has 1 nodes)");
  GltfText bad_mesh;
  bad_mesh.node(R"("name":"floor","mesh":4)");
  expect_refused(parse(bad_mesh.text_bytes()),
                 "node 0 'floor' refers to mesh 4, out of range (the file has 0 meshes)");
}

TEST(LevelFile, RefusesBadNodeTransforms) {
  expect_refused(parse(square_file(R"("matrix":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0])").text_bytes()),
                 "node 0 'floor': matrix has 15 numbers, expected 16");
  expect_refused(parse(square_file(R"("rotation":[0,0,0,0])").text_bytes()),
                 "node 0 'floor': rotation has zero length");
  expect_refused(parse(square_file(R"("translation":[1,2])").text_bytes()),
                 "node 0 'floor': translation has 2 numbers, expected 3");
}

TEST(LevelFile, BuffersFollowTheGltfImportersFileRules) {
  const fs::path dir = test::scratch_dir();
  GltfText file = square_file();
  std::string text = file.json(false);
  const std::string length = R"("byteLength":)" + std::to_string(file.bin_.size());
  text.replace(text.find(length), length.size(), length + R"(,"uri":"../outside.bin")");
  fs::create_directories(dir / "levels");
  std::ofstream(dir / "levels" / "escape.gltf") << text;
  expect_refused(load_level(dir / "levels" / "escape.gltf"),
                 "buffer 0 (uri '../outside.bin') leaves the glTF file's folder through '..'",
                 dir / "levels" / "escape.gltf");
  expect_refused(parse({text.begin(), text.end()}),
                 "buffer 0 (uri '../outside.bin') names a file, which is refused for glTF parsed "
                 "from memory");
  expect_refused(load_level(dir / "missing.gltf"), "cannot open the level file",
                 dir / "missing.gltf");
}

// ---------------------------------------------------------------------------------------------
// Level::validate, for levels made by hand

TEST(LevelValidate, AcceptsAnEmptyLevelAndAGoodOne) {
  EXPECT_TRUE(Level{}.validate().ok());
  Level level;
  level.positions = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}};
  level.indices = {0, 1, 2};
  EXPECT_TRUE(level.validate().ok()) << level.validate().message();
}

TEST(LevelValidate, RefusesEachBrokenRuleByName) {
  auto refused = [](const Level& level, const std::string& message) {
    const Status status = level.validate();
    ASSERT_FALSE(status.ok()) << "expected: " << message;
    EXPECT_EQ(status.message(), message);
  };
  Level level;
  level.positions = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}};
  level.indices = {0, 1, 2};

  Level broken = level;
  broken.indices.push_back(0);
  refused(broken, "the level has 4 indices, not a multiple of 3");
  broken = level;
  broken.indices[2] = 3;
  refused(broken, "triangle 0 names vertex 3, but the level has 3 vertices");
  broken = level;
  broken.positions[1].x = std::numeric_limits<float>::infinity();
  refused(broken, "vertex 1 lies at (inf, 0, 0) in the world: not finite or beyond ±100000 m");
  broken = level;
  broken.origin = {99999.5, 0.0, 0.0};
  refused(broken, "vertex 1 lies at (100000.5, 0, 0) in the world: not finite or beyond ±100000 m");
  broken = level;
  broken.origin.y = std::numeric_limits<double>::quiet_NaN();
  refused(broken, "the level's origin (0, nan, 0) is not finite or lies beyond ±100000 m");
  broken = level;
  broken.positions[2] = {2, 0, 0};
  refused(broken, "triangle 0 is degenerate: zero area");
}

}  // namespace
}  // namespace mm
