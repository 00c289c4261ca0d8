#ifndef MBSLAM_COMMON_CONFIG_OPTIONS_H_
#define MBSLAM_COMMON_CONFIG_OPTIONS_H_

// The options protocol. Every module has ONE options struct with in-class defaults,
// a comment with the unit on every field, and two members:
//
//   struct TrackerOptions {
//     int max_features = 1000;        // features kept per image (count)
//     double min_distance_px = 8.0;   // minimum spacing of features (px)
//
//     bool Check() const {
//       MBSLAM_CHECK_OPTION_GT(max_features, 0);
//       MBSLAM_CHECK_OPTION_GE(min_distance_px, 0.0);
//       return true;
//     }
//     template <typename Visitor>
//     void VisitFields(Visitor& v) {
//       v("max_features", &max_features, "features kept per image (count)");
//       v("min_distance_px", &min_distance_px, "minimum spacing of features (px)");
//     }
//   };
//
// VisitFields lets the YAML reader (options_yaml.h) fill the struct, reject unknown
// keys and print the effective configuration, without any per-field parsing code.
// Fields may be bool, int, int64_t, double, float, std::string, std::vector<double>,
// std::vector<std::string>, std::array<double, N>, or another options struct (a
// nested section). This header does not include YAML.

#include <sstream>
#include <string>
#include <type_traits>

namespace mbslam {

// The reason the last Check() on this thread failed ("tracking.max_features > 0
// failed: max_features = -3").
const std::string& LastOptionError();

namespace internal {
void SetOptionError(const std::string& message);

template <typename T, typename = void>
struct HasVisitFields : std::false_type {};

struct NullVisitor {
  template <typename F>
  void operator()(const char*, F*, const char*) {}
};

template <typename T>
struct HasVisitFields<T, std::void_t<decltype(std::declval<T&>().VisitFields(
                             std::declval<NullVisitor&>()))>> : std::true_type {};
}  // namespace internal

template <typename T>
inline constexpr bool kIsOptionsStruct = internal::HasVisitFields<T>::value;

}  // namespace mbslam

#define MBSLAM_CHECK_OPTION(cond)                                                   \
  do {                                                                              \
    if (!(cond)) {                                                                  \
      ::mbslam::internal::SetOptionError(std::string("option check failed: ") + #cond); \
      return false;                                                                 \
    }                                                                               \
  } while (0)

#define MBSLAM_CHECK_OPTION_OP(a, op, b)                                          \
  do {                                                                            \
    if (!((a)op(b))) {                                                            \
      std::ostringstream _mbslam_os;                                              \
      _mbslam_os << "option check failed: " #a " " #op " " #b " (" #a " = " << (a) \
                 << ")";                                                          \
      ::mbslam::internal::SetOptionError(_mbslam_os.str());                       \
      return false;                                                               \
    }                                                                             \
  } while (0)

#define MBSLAM_CHECK_OPTION_GT(a, b) MBSLAM_CHECK_OPTION_OP(a, >, b)
#define MBSLAM_CHECK_OPTION_GE(a, b) MBSLAM_CHECK_OPTION_OP(a, >=, b)
#define MBSLAM_CHECK_OPTION_LT(a, b) MBSLAM_CHECK_OPTION_OP(a, <, b)
#define MBSLAM_CHECK_OPTION_LE(a, b) MBSLAM_CHECK_OPTION_OP(a, <=, b)
#define MBSLAM_CHECK_OPTION_EQ(a, b) MBSLAM_CHECK_OPTION_OP(a, ==, b)

// Checks a nested options struct and prefixes its error with the section name.
#define MBSLAM_CHECK_OPTION_SECTION(section)                                    \
  do {                                                                          \
    if (!(section).Check()) {                                                   \
      ::mbslam::internal::SetOptionError(std::string(#section ": ") +           \
                                         ::mbslam::LastOptionError());          \
      return false;                                                             \
    }                                                                           \
  } while (0)

#endif  // MBSLAM_COMMON_CONFIG_OPTIONS_H_
