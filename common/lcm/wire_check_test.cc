#include "common/lcm/wire_check.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <sstream>

#include "common/lcm/all_types.h"

namespace mbslam {
namespace {

// Random valid encoding -> checker accepts -> generated decoder -> re-encode gives the
// same bytes. Then every truncation and a corrupted length are rejected.
template <typename Msg>
void CheckType() {
  SCOPED_TRACE(Msg::getTypeName());
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    const std::vector<uint8_t> bytes = RandomLcmEncoding(Msg::getTypeName(), Msg::getHash(), seed);
    ASSERT_FALSE(bytes.empty());
    ASSERT_TRUE(CheckLcmEncoding<Msg>(bytes.data(), bytes.size()).ok())
        << CheckLcmEncoding<Msg>(bytes.data(), bytes.size()).message();
    Msg msg;
    ASSERT_TRUE(DecodeLcmMessage(bytes.data(), bytes.size(), &msg).ok());
    std::vector<uint8_t> again(static_cast<size_t>(msg.getEncodedSize()));
    ASSERT_EQ(msg.encode(again.data(), 0, static_cast<int>(again.size())),
              static_cast<int>(again.size()));
    ASSERT_EQ(again, bytes);
    for (size_t cut = 0; cut < bytes.size(); cut += 1 + bytes.size() / 40) {
      EXPECT_FALSE(CheckLcmEncoding<Msg>(bytes.data(), cut).ok()) << "cut at " << cut;
      Msg m;
      EXPECT_FALSE(DecodeLcmMessage(bytes.data(), cut, &m).ok());
    }
    std::vector<uint8_t> longer = bytes;
    longer.push_back(0);
    EXPECT_FALSE(CheckLcmEncoding<Msg>(longer.data(), longer.size()).ok());
    std::vector<uint8_t> wrong_hash = bytes;
    wrong_hash[3] ^= 0x10;
    EXPECT_FALSE(CheckLcmEncoding<Msg>(wrong_hash.data(), wrong_hash.size()).ok());
  }
}

TEST(WireCheck, EveryTypeRoundTripsAndRejectsTruncation) {
#define MBSLAM_CHECK_TYPE(T) CheckType<mbslam::T>();
  MBSLAM_FOR_EACH_LCM_TYPE(MBSLAM_CHECK_TYPE)
#undef MBSLAM_CHECK_TYPE
}

TEST(WireCheck, TypeListMatchesTheLcmFiles) {
  std::set<std::string> listed;
#define MBSLAM_LIST_TYPE(T) listed.insert(#T);
  MBSLAM_FOR_EACH_LCM_TYPE(MBSLAM_LIST_TYPE)
#undef MBSLAM_LIST_TYPE
  std::set<std::string> schema;
  std::istringstream names(LcmSchemaTypeNames());
  for (std::string n; names >> n;) schema.insert(n);
  EXPECT_EQ(listed, schema);
}

// A header claiming a 2 GB image must be rejected before anything allocates it.
TEST(WireCheck, HugeLengthIsRejectedBeforeAllocation) {
  mbslam::image_t img;
  img.utime = 1;
  img.seq = 2;
  img.camera_name = "cam";
  img.width = 2;
  img.height = 2;
  img.row_stride = 2;
  img.encoding = mbslam::image_t::ENCODING_GRAY8;
  img.data = {1, 2, 3, 4};
  img.size = 4;
  std::vector<uint8_t> bytes(static_cast<size_t>(img.getEncodedSize()));
  img.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  // The size field sits just before the 4 data bytes.
  const size_t size_pos = bytes.size() - 4 - 4;
  for (uint32_t claimed : {0x7fffffffu, 0x80000000u, 5u}) {
    std::vector<uint8_t> bad = bytes;
    bad[size_pos] = static_cast<uint8_t>(claimed >> 24);
    bad[size_pos + 1] = static_cast<uint8_t>(claimed >> 16);
    bad[size_pos + 2] = static_cast<uint8_t>(claimed >> 8);
    bad[size_pos + 3] = static_cast<uint8_t>(claimed);
    mbslam::image_t out;
    const Status s = DecodeLcmMessage(bad.data(), bad.size(), &out);
    EXPECT_FALSE(s.ok()) << claimed;
    EXPECT_TRUE(out.data.empty());
  }
}

TEST(WireCheck, OversizedMessageIsRejected) {
  std::vector<uint8_t> big(1000, 0);
  mbslam::image_t out;
  EXPECT_FALSE(DecodeLcmMessage(big.data(), big.size(), &out, /*max_size=*/100).ok());
}

// Regression (fuzz_lcm_decode, issue 9): a string with a NUL inside decoded to a longer
// std::string than lcm-gen's encoder writes back (it stops at the first NUL while
// getEncodedSize() counts every byte), so a re-published or logged copy of the message
// was malformed and carried unwritten buffer bytes. Such strings are rejected.
TEST(WireCheck, StringWithAnInnerNulIsRejected) {
  mbslam::snapshot_request_t r;
  r.utime = 1;
  r.path_prefix = std::string("snap\0/x", 7);
  r.what = 4;
  std::vector<uint8_t> bytes(static_cast<size_t>(r.getEncodedSize()));
  r.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  // What a sender that copies the bytes (not lcm-gen's encoder) puts on the wire.
  const size_t len_pos = 8 + 8;
  bytes[len_pos + 3] = 8;
  std::copy_n("snap\0/x", 8, bytes.begin() + static_cast<long>(len_pos + 4));
  mbslam::snapshot_request_t out;
  const Status s = DecodeLcmMessage(bytes.data(), bytes.size(), &out);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("NUL byte inside"), std::string::npos) << s.message();

  r.path_prefix = "snap/x";
  std::vector<uint8_t> good(static_cast<size_t>(r.getEncodedSize()));
  r.encode(good.data(), 0, static_cast<int>(good.size()));
  ASSERT_TRUE(DecodeLcmMessage(good.data(), good.size(), &out).ok());
  EXPECT_EQ(out.path_prefix, "snap/x");
}

}  // namespace
}  // namespace mbslam
