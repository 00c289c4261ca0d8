#include "common/config/options.h"

namespace mbslam {
namespace {
thread_local std::string g_last_option_error;
}  // namespace

const std::string& LastOptionError() { return g_last_option_error; }

namespace internal {
void SetOptionError(const std::string& message) { g_last_option_error = message; }
}  // namespace internal

}  // namespace mbslam
