#include "mm/database/files.hpp"

#include <sys/mman.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>

namespace mm {

namespace {

std::string system_error_text() {
  return std::strerror(errno);
}

}  // namespace

Result<FileContents> read_whole_file(const std::filesystem::path& path, std::string_view what) {
  const std::string name = path.string();
  std::error_code ignored;
  if (std::filesystem::is_directory(path, ignored)) {
    return Error{name + ": cannot read the " + std::string(what) + " (it is a folder)"};
  }
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(name.c_str(), "rb"),
                                                       &std::fclose);
  if (!file) {
    return Error{name + ": cannot open the " + std::string(what) + " (" + system_error_text() +
                 ")"};
  }
  // Sized from the file size, but read until EOF in case the file changes under us.
  std::error_code size_error;
  const uintmax_t size_hint = std::filesystem::file_size(path, size_error);
  size_t capacity = size_error ? size_t{1} << 16 : static_cast<size_t>(size_hint) + 1;
  FileContents contents;
  contents.data = std::make_unique_for_overwrite<char[]>(capacity + 1);
  for (;;) {
    if (contents.size == capacity) {
      const size_t grown = capacity * 2;
      auto bigger = std::make_unique_for_overwrite<char[]>(grown + 1);
      std::memcpy(bigger.get(), contents.data.get(), contents.size);
      contents.data = std::move(bigger);
      capacity = grown;
    }
    const size_t wanted = capacity - contents.size;
    const size_t got = std::fread(contents.data.get() + contents.size, 1, wanted, file.get());
    contents.size += got;
    if (got < wanted) {
      if (std::ferror(file.get())) {
        return Error{name + ": cannot read the " + std::string(what) + " (" + system_error_text() +
                     ")"};
      }
      break;
    }
  }
  contents.data[contents.size] = '\0';
  return contents;
}

Status write_whole_file(const std::filesystem::path& path, std::string_view bytes,
                        std::string_view what) {
  const std::string name = path.string();
  const std::string failed = name + ": cannot write the " + std::string(what) + " (";
  std::error_code ignored;
  // Worded as read_whole_file words it, rather than the system's "Is a directory".
  if (std::filesystem::is_directory(path, ignored)) return Error{failed + "it is a folder)"};
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(name.c_str(), "wb"),
                                                       &std::fclose);
  if (!file) return Error{failed + system_error_text() + ")"};
  if (std::fwrite(bytes.data(), 1, bytes.size(), file.get()) != bytes.size()) {
    return Error{failed + system_error_text() + ")"};
  }
  // Buffered bytes reach the disk at fclose: a full disk is only reported there.
  if (std::fclose(file.release()) != 0) return Error{failed + system_error_text() + ")"};
  return Status::success();
}

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool has_extension(const std::filesystem::path& path,
                   std::initializer_list<std::string_view> extensions) {
  const std::string ext = lower_extension(path);
  for (std::string_view candidate : extensions) {
    if (ext == candidate) return true;
  }
  return false;
}

std::string format_bytes(uint64_t bytes) {
  char text[32];
  const double b = static_cast<double>(bytes);
  if (bytes >= 1000000000) {
    std::snprintf(text, sizeof text, "%.1f GB", b / 1e9);
  } else if (bytes >= 1000000) {
    std::snprintf(text, sizeof text, "%.1f MB", b / 1e6);
  } else if (bytes >= 1000) {
    std::snprintf(text, sizeof text, "%.1f KB", b / 1e3);
  } else {
    std::snprintf(text, sizeof text, "%llu B", static_cast<unsigned long long>(bytes));
  }
  return text;
}

void advise_huge_pages(void* data, size_t bytes) {
#ifdef MADV_HUGEPAGE
  constexpr uintptr_t kHugePage = uintptr_t{2} << 20;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kHugePage - 1) & ~(kHugePage - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kHugePage - 1);
  if (end > begin) (void)::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

}  // namespace mm
