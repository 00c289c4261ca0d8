#ifndef MBSLAM_TEST_FUZZ_FUZZ_UTIL_H_
#define MBSLAM_TEST_FUZZ_FUZZ_UTIL_H_

// Helpers shared by the fuzz targets in test/fuzz (one LLVMFuzzerTestOneInput each).
//
// Inputs that carry several pieces (a sequence of LCM messages, two files of a
// dataset) are framed as records: one tag byte, a 4-byte little-endian length
// (clamped to what is left, so every byte string is a valid input), the bytes.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace mbslam {
namespace fuzz {

struct Record {
  uint8_t tag = 0;
  const uint8_t* data = nullptr;
  size_t size = 0;
};

// At most max_records records; a trailing fragment shorter than a header is ignored.
std::vector<Record> SplitRecords(const uint8_t* data, size_t size, size_t max_records = 64);
void AppendRecord(uint8_t tag, const uint8_t* data, size_t size, std::vector<uint8_t>* out);

// A directory private to this process, removed at exit (common/testing/temp_dir.h),
// for readers that take paths.
// Write() replaces a file's content and returns its path.
class ScratchDir {
 public:
  static ScratchDir& Get();
  const std::string& path() const { return path_; }
  std::string Write(const std::string& name, const uint8_t* data, size_t size);
  std::string Write(const std::string& name, const std::string& text) {
    return Write(name, reinterpret_cast<const uint8_t*>(text.data()), text.size());
  }
  // Creates an (empty) file or a folder below the scratch directory.
  std::string Touch(const std::string& name);
  std::string MakeDir(const std::string& name);

 private:
  ScratchDir();
  std::string path_;
};

// Logging of the product code down to errors only (a bad input logs a warning, and
// printing one per execution would dominate the fuzzer's time).
void QuietLogs();

// Aborts with a message: a property the target checks does not hold.
[[noreturn]] void Fail(const char* what);

}  // namespace fuzz
}  // namespace mbslam

#endif  // MBSLAM_TEST_FUZZ_FUZZ_UTIL_H_
