#include "test/fuzz/fuzz_util.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <opencv2/core/utils/logger.hpp>

#include "common/testing/temp_dir.h"
#include "common/util/logging.h"

namespace mbslam {
namespace fuzz {

std::vector<Record> SplitRecords(const uint8_t* data, size_t size, size_t max_records) {
  std::vector<Record> records;
  size_t pos = 0;
  while (pos + 5 <= size && records.size() < max_records) {
    Record r;
    r.tag = data[pos];
    const uint32_t length = static_cast<uint32_t>(data[pos + 1]) |
                            static_cast<uint32_t>(data[pos + 2]) << 8 |
                            static_cast<uint32_t>(data[pos + 3]) << 16 |
                            static_cast<uint32_t>(data[pos + 4]) << 24;
    pos += 5;
    r.size = std::min<size_t>(length, size - pos);
    r.data = data + pos;
    pos += r.size;
    records.push_back(r);
  }
  return records;
}

void AppendRecord(uint8_t tag, const uint8_t* data, size_t size, std::vector<uint8_t>* out) {
  out->push_back(tag);
  for (int b = 0; b < 4; ++b) out->push_back(static_cast<uint8_t>(size >> (8 * b)));
  out->insert(out->end(), data, data + size);
}

ScratchDir& ScratchDir::Get() {
  static ScratchDir dir;
  return dir;
}

ScratchDir::ScratchDir() : path_(testing_util::MakeTestTempDir("fuzz")) {}

std::string ScratchDir::Write(const std::string& name, const uint8_t* data, size_t size) {
  const std::string file = path_ + "/" + name;
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out) Fail("cannot write a scratch file");
  return file;
}

std::string ScratchDir::Touch(const std::string& name) {
  return Write(name, nullptr, 0);
}

std::string ScratchDir::MakeDir(const std::string& name) {
  const std::string dir = path_ + "/" + name;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) Fail("cannot create a scratch folder");
  return dir;
}

void QuietLogs() {
  SetLogLevel(LogLevel::kError);
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
}

void Fail(const char* what) {
  std::fprintf(stderr, "fuzz target property violated: %s\n", what);
  std::abort();
}

}  // namespace fuzz
}  // namespace mbslam
