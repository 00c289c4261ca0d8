#ifndef MBSLAM_COMMON_UTIL_STATUS_H_
#define MBSLAM_COMMON_UTIL_STATUS_H_

#include <string>
#include <utility>

namespace mbslam {

// Result of an operation that can fail on bad input or environment. Library code
// returns it; only main() decides to exit.
class Status {
 public:
  Status() = default;
  static Status Ok() { return Status(); }
  static Status Error(std::string message) { return Status(std::move(message)); }

  bool ok() const { return !failed_; }
  const std::string& message() const { return message_; }
  explicit operator bool() const { return ok(); }

  // Prefixes the message with context ("reading config.yaml: ...").
  Status WithContext(const std::string& context) const {
    if (ok()) return *this;
    return Status(context + ": " + message_);
  }

 private:
  explicit Status(std::string message) : failed_(true), message_(std::move(message)) {}
  bool failed_ = false;
  std::string message_;
};

}  // namespace mbslam

#define MBSLAM_RETURN_IF_ERROR(expr)        \
  do {                                      \
    ::mbslam::Status _mbslam_status = (expr); \
    if (!_mbslam_status.ok()) return _mbslam_status; \
  } while (0)

#endif  // MBSLAM_COMMON_UTIL_STATUS_H_
