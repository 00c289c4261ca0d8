#ifndef MBSLAM_COMMON_LCM_WIRE_CHECK_H_
#define MBSLAM_COMMON_LCM_WIRE_CHECK_H_

// Validates an LCM-encoded message against its .lcm definition BEFORE lcm-gen's
// decoder runs. The generated decoders resize every array to the length the message
// claims and only then check that the bytes exist, so a corrupt length field can
// make them allocate gigabytes. The checker walks the encoding with the schema of the
// .lcm files (embedded into the binary at build time) and rejects any array or string
// longer than the bytes that remain, negative lengths, missing NUL terminators, NUL
// bytes inside strings, a wrong type fingerprint and trailing garbage.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "common/util/status.h"

namespace mbslam {

// `type_name` is the bare type name ("image_t"); `expected_hash` is Msg::getHash().
Status CheckLcmEncoding(const std::string& type_name, int64_t expected_hash, const uint8_t* data,
                        size_t size);

template <typename Msg>
Status CheckLcmEncoding(const uint8_t* data, size_t size) {
  return CheckLcmEncoding(Msg::getTypeName(), Msg::getHash(), data, size);
}

// Decodes a message after CheckLcmEncoding; never throws. `max_size` bounds the raw
// message before anything is looked at.
template <typename Msg>
Status DecodeLcmMessage(const uint8_t* data, size_t size, Msg* msg,
                        size_t max_size = size_t{64} << 20) {
  if (size > max_size) {
    return Status::Error(std::string(Msg::getTypeName()) + ": message of " +
                         std::to_string(size) + " bytes exceeds the limit of " +
                         std::to_string(max_size));
  }
  MBSLAM_RETURN_IF_ERROR(CheckLcmEncoding<Msg>(data, size));
  try {
    if (msg->decode(data, 0, static_cast<int>(size)) != static_cast<int>(size)) {
      return Status::Error(std::string(Msg::getTypeName()) + ": decode failed");
    }
  } catch (const std::exception& e) {
    return Status::Error(std::string(Msg::getTypeName()) + ": decode threw: " + e.what());
  }
  return Status::Ok();
}

// The encoding of a message (the counterpart of DecodeLcmMessage), for tests, tools and
// log writers.
template <typename Msg>
std::vector<uint8_t> EncodeLcmMessage(const Msg& msg) {
  std::vector<uint8_t> buf(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
  return buf;
}

// The names of all types in the embedded schema, space separated (for tests and tools).
std::string LcmSchemaTypeNames();

// A random but valid encoding of a type (fingerprint included), from the schema:
// arrays get 0..max_array elements, strings printable text, numbers finite values.
// For round-trip tests and fuzz corpora.
std::vector<uint8_t> RandomLcmEncoding(const std::string& type_name, int64_t hash,
                                       uint32_t seed, int max_array = 4);

}  // namespace mbslam

#endif  // MBSLAM_COMMON_LCM_WIRE_CHECK_H_
