#include "gltf_files.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <system_error>
#include <utility>

#include <nlohmann/json.hpp>

#include "mm/database/files.hpp"
#include "mm/offline/gltf.hpp"

namespace mm::gltf_files {
namespace {

namespace fs = std::filesystem;

// One buffer that names a file, as the JSON gives it.
struct FileBuffer {
  size_t index = 0;
  std::string uri;                      // as written, for messages
  std::optional<uint64_t> byte_length;  // absent when missing or not an unsigned integer
};

// tinygltf percent-decodes a buffer's uri (and turns '+' into a space) before looking the file
// up; its decoder is not part of its interface, so this repeats it, malformed escapes included
// (a non-hex digit counts as 0), so that both name the same file.
std::string decode_uri(std::string_view uri) {
  auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return 0;
  };
  std::string out;
  out.reserve(uri.size());
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '+') {
      out += ' ';
    } else if (uri[i] == '%' && uri.size() > i + 2) {
      out += static_cast<char>((hex(uri[i + 1]) << 4) | hex(uri[i + 2]));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

// The buffers whose uri is not a data: URI (a GLB's own chunk has no uri).
std::vector<FileBuffer> file_buffers(const nlohmann::json& document) {
  std::vector<FileBuffer> found;
  if (!document.is_object()) return found;
  const auto buffers = document.find("buffers");
  if (buffers == document.end() || !buffers->is_array()) return found;
  for (size_t i = 0; i < buffers->size(); ++i) {
    const nlohmann::json& buffer = (*buffers)[i];
    if (!buffer.is_object()) continue;
    const auto uri = buffer.find("uri");
    if (uri == buffer.end() || !uri->is_string()) continue;
    const std::string& text = uri->get_ref<const std::string&>();
    if (text.empty() || text.starts_with("data:")) continue;
    FileBuffer file{i, text, std::nullopt};
    const auto length = buffer.find("byteLength");
    if (length != buffer.end() && length->is_number_unsigned()) {
      file.byte_length = length->get<uint64_t>();
    }
    found.push_back(std::move(file));
  }
  return found;
}

std::string file_kind(fs::file_type type) {
  switch (type) {
    case fs::file_type::directory:
      return "a folder";
    case fs::file_type::fifo:
      return "a FIFO";
    case fs::file_type::socket:
      return "a socket";
    case fs::file_type::block:
      return "a block device";
    case fs::file_type::character:
      return "a character device";
    default:
      return "not a file";
  }
}

// "buffer 2 (uri 'walk.bin')", the uri cut short if a hostile file made it huge.
std::string buffer_label(const FileBuffer& buffer) {
  constexpr size_t kShown = 200;
  const std::string uri =
      buffer.uri.size() > kShown ? buffer.uri.substr(0, kShown) + "..." : buffer.uri;
  return "buffer " + std::to_string(buffer.index) + " (uri '" + uri + "')";
}

// Where the buffer's file is, once it is known to be a regular file inside `folder` (canonical)
// whose size is its byteLength and within the cap; or why it is refused. Opens nothing.
Result<fs::path> check_file(const FileBuffer& buffer, const std::string& decoded,
                            const fs::path& folder) {
  const std::string label = buffer_label(buffer);
  if (decoded.find('\0') != std::string::npos) {
    return Error{label + " contains a NUL character"};
  }
  const fs::path relative(decoded);
  if (relative.has_root_name() || relative.has_root_directory()) {
    return Error{label + " is an absolute path; buffers may only name files inside the glTF " +
                 "file's folder, by a relative path"};
  }
  const fs::path normal = relative.lexically_normal();
  if (normal.empty() || *normal.begin() == "..") {
    return Error{label + " leaves the glTF file's folder through '..'"};
  }
  if (!buffer.byte_length) return Error{label + " has no byteLength (an unsigned integer)"};
  std::error_code error;
  const fs::path target = fs::canonical(folder / normal, error);
  if (error) return Error{label + " cannot be opened (" + error.message() + ")"};
  const fs::path inside = target.lexically_relative(folder);
  if (inside.empty() || *inside.begin() == "..") {
    return Error{label + " resolves (through a symbolic link) to " + target.string() +
                 ", outside the glTF file's folder"};
  }
  const fs::file_status status = fs::status(target, error);
  if (error) return Error{label + " cannot be opened (" + error.message() + ")"};
  if (status.type() != fs::file_type::regular) {
    return Error{label + " is not a regular file (it is " + file_kind(status.type()) + ")"};
  }
  const uintmax_t size = fs::file_size(target, error);
  if (error) return Error{label + " cannot be opened (" + error.message() + ")"};
  if (size > kGltfMaxExternalBufferBytes) {
    return Error{label + " is " + std::to_string(size) + " bytes, above the cap of " +
                 std::to_string(kGltfMaxExternalBufferBytes) + " bytes on external buffers"};
  }
  if (size != *buffer.byte_length) {
    return Error{label + " is " + std::to_string(size) + " bytes but its byteLength says " +
                 std::to_string(*buffer.byte_length)};
  }
  return target;
}

// Reads exactly `size` bytes of a file check_file accepted. Opened without blocking and
// checked again on the open descriptor, so a file swapped for a FIFO or resized after the
// check is refused rather than waited on or over-read.
Result<std::vector<unsigned char>> read_checked_file(const fs::path& path, uint64_t size,
                                                     const std::string& label) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) {
    return Error{label + " cannot be opened (" + std::generic_category().message(errno) + ")"};
  }
  struct stat info {};
  const bool same = ::fstat(fd, &info) == 0 && S_ISREG(info.st_mode) &&
                    static_cast<uint64_t>(info.st_size) == size;
  std::vector<unsigned char> bytes;
  std::string failure = same ? "" : " changed while it was being opened";
  if (same) bytes.resize(static_cast<size_t>(size));
  for (size_t done = 0; same && done < bytes.size();) {
    const ssize_t got = ::read(fd, bytes.data() + done, bytes.size() - done);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) {
      failure = got < 0 ? " cannot be read (" + std::generic_category().message(errno) + ")"
                        : " ended before its byteLength while it was being read";
      break;
    }
    done += static_cast<size_t>(got);
  }
  ::close(fd);
  if (!failure.empty()) return Error{label + failure};
  return bytes;
}

bool file_exists(const std::string& name, void* user) {
  return static_cast<ExternalFiles*>(user)->files.contains(name);
}

std::string expand_file_path(const std::string& name, void*) {
  return name;  // tinygltf's own expands "~" and "$VARIABLES" (wordexp); a uri means itself
}

bool read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& name,
                     void* user) {
  auto& files = static_cast<ExternalFiles*>(user)->files;
  const auto found = files.find(name);
  if (found == files.end() || found->second.readers <= 0) {
    if (err) *err += "not one of the files the buffers may name";
    return false;
  }
  // The last buffer naming a file takes its bytes; earlier ones (the same uri twice) copy them.
  if (--found->second.readers == 0) {
    *out = std::move(found->second.bytes);
  } else {
    *out = found->second.bytes;
  }
  return true;
}

bool refuse_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "the glTF importer writes no files";
  return false;
}

}  // namespace

Result<ExternalFiles> read_external_buffers(std::string_view json, const fs::path& folder,
                                            bool allow_files) {
  const nlohmann::json document =
      nlohmann::json::parse(json.begin(), json.end(), nullptr, /*allow_exceptions=*/false);
  const std::vector<FileBuffer> buffers = file_buffers(document);
  ExternalFiles external;
  if (buffers.empty()) return external;
  if (!allow_files) {
    return Error{buffer_label(buffers.front()) + " names a file, which is refused for glTF " +
                 "parsed from memory (only data: URIs and the GLB binary chunk are read)"};
  }
  std::error_code error;
  const fs::path canonical_folder = fs::canonical(folder.empty() ? "." : folder, error);
  if (error) {
    return Error{"cannot resolve the glTF file's folder " + folder.string() + " (" +
                 error.message() + ") to check buffer uris"};
  }
  // Every buffer is checked before any file is opened, so a refusal reads nothing at all.
  std::vector<fs::path> targets;
  uint64_t total = 0;
  for (const FileBuffer& buffer : buffers) {
    auto target = check_file(buffer, decode_uri(buffer.uri), canonical_folder);
    if (!target) return target.error();
    total += *buffer.byte_length;
    if (total > kGltfMaxExternalBufferBytes) {
      return Error{buffer_label(buffer) + " brings the external buffers to " +
                   std::to_string(total) + " bytes, above the cap of " +
                   std::to_string(kGltfMaxExternalBufferBytes) + " bytes on external buffers"};
    }
    targets.push_back(std::move(*target));
  }
  for (size_t i = 0; i < buffers.size(); ++i) {
    ExternalFiles::File& file = external.files[decode_uri(buffers[i].uri)];
    if (file.readers++ > 0) continue;  // the same file again: read once
    auto bytes = read_checked_file(targets[i], *buffers[i].byte_length, buffer_label(buffers[i]));
    if (!bytes) return bytes.error();
    file.bytes = std::move(*bytes);
  }
  return external;
}

tinygltf::FsCallbacks confined_callbacks(ExternalFiles& files) {
  return {&file_exists, &expand_file_path, &read_whole_file, &refuse_write, &files};
}

int components_in_type(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
      return 4;
    case TINYGLTF_TYPE_MAT2:
      return 4;
    case TINYGLTF_TYPE_MAT3:
      return 9;
    case TINYGLTF_TYPE_MAT4:
      return 16;
    default:
      return 0;
  }
}

std::string type_name(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
      return "VEC2";
    case TINYGLTF_TYPE_VEC3:
      return "VEC3";
    case TINYGLTF_TYPE_VEC4:
      return "VEC4";
    case TINYGLTF_TYPE_MAT2:
      return "MAT2";
    case TINYGLTF_TYPE_MAT3:
      return "MAT3";
    case TINYGLTF_TYPE_MAT4:
      return "MAT4";
    default:
      return "unknown type (" + std::to_string(type) + ")";
  }
}

int component_size(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}

std::string component_name(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
      return "BYTE";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return "UNSIGNED_BYTE";
    case TINYGLTF_COMPONENT_TYPE_SHORT:
      return "SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return "UNSIGNED_SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return "UNSIGNED_INT";
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return "FLOAT";
    default:
      return "unknown component type (" + std::to_string(component_type) + ")";
  }
}

Result<size_t> check_glb_container(std::span<const unsigned char> bytes) {
  auto u32 = [&](size_t offset) {
    uint32_t v;
    std::memcpy(&v, bytes.data() + offset, sizeof v);
    return v;
  };
  if (bytes.size() < 12) {
    return Error{"binary glTF (GLB) is truncated: " + std::to_string(bytes.size()) +
                 " bytes, shorter than the 12-byte header"};
  }
  if (u32(4) != 2) {
    return Error{"binary glTF (GLB) version " + std::to_string(u32(4)) +
                 " is not supported (expected 2)"};
  }
  const size_t length = u32(8);
  if (length != bytes.size()) {
    return Error{"binary glTF (GLB) header says the file has " + std::to_string(length) +
                 " bytes but it has " + std::to_string(bytes.size()) +
                 (length > bytes.size() ? " (truncated?)" : "")};
  }
  size_t offset = 12;
  int chunk = 0;
  while (offset < length) {
    if (length - offset < 8) {
      return Error{"binary glTF (GLB) is truncated: chunk " + std::to_string(chunk) +
                   " header at byte " + std::to_string(offset) + " is incomplete"};
    }
    const size_t chunk_length = u32(offset);
    const uint32_t chunk_type = u32(offset + 4);
    if (chunk_length > length - offset - 8) {
      return Error{"binary glTF (GLB) is truncated: chunk " + std::to_string(chunk) + " at byte " +
                   std::to_string(offset) + " claims " + std::to_string(chunk_length) +
                   " bytes but only " + std::to_string(length - offset - 8) + " remain"};
    }
    if (chunk == 0 && (chunk_type != 0x4E4F534Au || chunk_length == 0)) {
      return Error{"binary glTF (GLB): the first chunk must be a non-empty JSON chunk"};
    }
    offset += 8 + chunk_length;
    ++chunk;
  }
  if (chunk == 0) return Error{"binary glTF (GLB) has no JSON chunk"};
  return length;
}

size_t glb_json_chunk_length(std::span<const unsigned char> bytes) {
  uint32_t length;
  std::memcpy(&length, bytes.data() + 12, sizeof length);
  return length;
}

bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                const unsigned char*, int, void*) {
  return true;
}

Result<tinygltf::Model> load_model(std::span<const unsigned char> bytes,
                                   const std::filesystem::path& path, bool allow_external_files) {
  if (bytes.size() > std::numeric_limits<unsigned int>::max()) {
    return Error{"file is larger than 4 GiB, which glTF cannot address"};
  }
  const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  std::span<const unsigned char> json = bytes;
  if (binary) {
    auto length = check_glb_container(bytes);
    if (!length) return length.error();
    json = bytes.subspan(20, glb_json_chunk_length(bytes));
  } else if (lower_extension(path) == ".glb") {
    return Error{"not a binary glTF file (it does not start with the \"glTF\" magic)"};
  }
  // Every file a buffer names is checked and read before tinygltf runs; tinygltf itself opens
  // nothing (confined_callbacks), so the base folder it is given stays empty.
  auto external = gltf_files::read_external_buffers(
      std::string_view(reinterpret_cast<const char*>(json.data()), json.size()), path.parent_path(),
      allow_external_files);
  if (!external) return external.error();

  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(&skip_image, nullptr);
  loader.SetFsCallbacks(gltf_files::confined_callbacks(*external));
  std::string err;
  std::string warn;
  const bool loaded = binary
                          ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(),
                                                        static_cast<unsigned int>(bytes.size()), "")
                          : loader.LoadASCIIFromString(&model, &err, &warn,
                                                       reinterpret_cast<const char*>(bytes.data()),
                                                       static_cast<unsigned int>(bytes.size()), "");
  if (!loaded) {
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    return Error{"not a valid glTF 2.0 file: " +
                 (err.empty() ? std::string("unknown error") : err)};
  }
  return model;
}

}  // namespace mm::gltf_files
