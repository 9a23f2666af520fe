// libFuzzer target for the glTF importer, structure aware: inputs are GLB files, and a custom
// mutator keeps them GLB files. It splits the container into its JSON chunk and its binary
// chunk, changes one of them, and reassembles a well-formed container (header, chunk lengths,
// 4-byte padding), so the fuzzer's effort goes past check_glb_container and tinygltf's JSON
// parser into the importer's own checks (indices, accessors, samplers, the skin, the mesh).
// The change is one of:
// - libFuzzer's byte mutation of the JSON text or of the binary chunk;
// - an edit of one JSON value, parsed with nlohmann-json: a number nudged or replaced by an
//   edge value, a string replaced by a glTF keyword, an array element dropped or repeated, a
//   member dropped, or the value replaced by a copy of another value of the document.
// Inputs that are not a GLB (libFuzzer's own crossover can make them) get a byte mutation.
// Checked: the contract of gltf_fuzz_common.hpp. Seeds: exported .glb files
// (LLVMFuzzerInitialize writes them into the corpus).
//
// Run: scripts/fuzz.sh, or cmake --build build/fuzz --target fuzz_run_gltf_structure.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gltf_fuzz_common.hpp"

extern "C" size_t LLVMFuzzerMutate(uint8_t* data, size_t size, size_t max_size);

namespace {

using Json = nlohmann::json;

constexpr uint32_t kJsonChunk = 0x4E4F534Au;  // "JSON"
constexpr uint32_t kBinChunk = 0x004E4942u;   // "BIN\0"

struct Glb {
  std::string json;
  std::vector<unsigned char> bin;
  bool has_bin = false;
};

uint32_t read_u32(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

void append_u32(std::vector<unsigned char>& out, uint32_t v) {
  unsigned char bytes[4];
  std::memcpy(bytes, &v, sizeof v);
  out.insert(out.end(), bytes, bytes + 4);
}

// The two chunks of a well-formed GLB (a JSON chunk, then at most one BIN chunk), or none.
std::optional<Glb> split(const uint8_t* data, size_t size) {
  if (size < 20 || std::memcmp(data, "glTF", 4) != 0 || read_u32(data + 8) != size) return {};
  Glb glb;
  size_t offset = 12;
  for (int chunk = 0; offset < size; ++chunk) {
    if (size - offset < 8) return {};
    const size_t length = read_u32(data + offset);
    const uint32_t type = read_u32(data + offset + 4);
    if (length > size - offset - 8) return {};
    const uint8_t* body = data + offset + 8;
    if (chunk == 0 && type == kJsonChunk) {
      glb.json.assign(reinterpret_cast<const char*>(body), length);
    } else if (chunk == 1 && type == kBinChunk) {
      glb.bin.assign(body, body + length);
      glb.has_bin = true;
    } else {
      return {};
    }
    offset += 8 + length;
  }
  return glb;
}

// The container around the chunks: JSON padded with spaces, BIN with zeros, as GLB requires.
std::vector<unsigned char> assemble(const Glb& glb) {
  std::string json = glb.json;
  json.resize((json.size() + 3) / 4 * 4, ' ');
  std::vector<unsigned char> bin = glb.bin;
  bin.resize((bin.size() + 3) / 4 * 4, 0);
  std::vector<unsigned char> out;
  out.insert(out.end(), {'g', 'l', 'T', 'F'});
  append_u32(out, 2);
  append_u32(out, 0);  // the total length, set below
  append_u32(out, static_cast<uint32_t>(json.size()));
  append_u32(out, kJsonChunk);
  out.insert(out.end(), json.begin(), json.end());
  if (glb.has_bin) {
    append_u32(out, static_cast<uint32_t>(bin.size()));
    append_u32(out, kBinChunk);
    out.insert(out.end(), bin.begin(), bin.end());
  }
  const uint32_t total = static_cast<uint32_t>(out.size());
  std::memcpy(out.data() + 8, &total, sizeof total);
  return out;
}

// libFuzzer's byte mutation of a string or byte vector, allowed to grow it by up to `room`.
template <class Bytes>
void mutate_bytes(Bytes& bytes, size_t room) {
  const size_t size = bytes.size();
  bytes.resize(size + room);
  bytes.resize(LLVMFuzzerMutate(reinterpret_cast<uint8_t*>(bytes.data()), size, bytes.size()));
}

// Every value of the document, parents before children.
void collect(Json& value, std::vector<Json*>& out) {
  out.push_back(&value);
  if (value.is_structured()) {
    for (Json& child : value) collect(child, out);
  }
}

Json edited_number(const Json& value, std::minstd_rand& rng) {
  if (value.is_number_float()) {
    const double v = value.get<double>();
    const double choices[] = {-v, 0.0, 1e30, -1e-30, v + 0.5, v * 1e6, 1e308};
    return choices[rng() % std::size(choices)];
  }
  const int64_t v = value.get<int64_t>();
  const int64_t choices[] = {v + 1,     v - 1,      0,          -1,
                             v * 2,     4294967295, 2147483648, static_cast<int64_t>(rng() % 16),
                             1000000000};
  return choices[rng() % std::size(choices)];
}

Json edited_string(std::minstd_rand& rng) {
  const char* choices[] = {
      "LINEAR",   "STEP",      "CUBICSPLINE", "translation",
      "rotation", "scale",     "weights",     "SCALAR",
      "VEC3",     "VEC4",      "MAT4",        "",
      "2.0",      "other.bin", "../up.bin",   "data:application/octet-stream;base64,AAAAAAAAgD8="};
  return choices[rng() % std::size(choices)];
}

// One edit of one value of the JSON text; false when the text is not JSON.
bool edit_json(std::string& text, std::minstd_rand& rng) {
  Json document = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (document.is_discarded()) return false;
  std::vector<Json*> values;
  collect(document, values);
  Json& target = *values[rng() % values.size()];
  switch (rng() % 4) {
    case 0:  // replace by a copy of another value: indices, accessors and samplers cross over
      target = Json(*values[rng() % values.size()]);
      break;
    case 1:
      if (target.is_array() && !target.empty()) {
        const size_t i = rng() % target.size();
        if (rng() % 2) {
          target.erase(i);
        } else {
          target.push_back(Json(target[i]));
        }
        break;
      }
      [[fallthrough]];
    case 2:
      if (target.is_object() && !target.empty()) {
        auto member = target.begin();
        std::advance(member, static_cast<std::ptrdiff_t>(rng() % target.size()));
        target.erase(member);
        break;
      }
      [[fallthrough]];
    default:
      target = target.is_number() ? edited_number(target, rng) : edited_string(rng);
      break;
  }
  text = document.dump(-1, ' ', false, Json::error_handler_t::replace);
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  mm::fuzz::write_seeds(*argc, *argv, /*text_too=*/false);
  return 0;
}

extern "C" size_t LLVMFuzzerCustomMutator(uint8_t* data, size_t size, size_t max_size,
                                          unsigned int seed) {
  std::optional<Glb> glb = split(data, size);
  if (!glb) return LLVMFuzzerMutate(data, size, max_size);
  std::minstd_rand rng(seed);
  const size_t room = max_size > size ? max_size - size : 0;
  switch (rng() % 4) {
    case 0:
      mutate_bytes(glb->json, room);
      break;
    case 1:
      glb->has_bin = true;
      mutate_bytes(glb->bin, room);
      break;
    default:
      if (!edit_json(glb->json, rng)) mutate_bytes(glb->json, room);
      break;
  }
  const std::vector<unsigned char> out = assemble(*glb);
  if (out.size() > max_size) return LLVMFuzzerMutate(data, size, max_size);
  std::memcpy(data, out.data(), out.size());
  return out.size();
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  mm::fuzz::parse_and_check(std::span<const unsigned char>(data, size));
  return 0;
}
