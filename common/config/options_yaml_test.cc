#include "common/config/options_yaml.h"

#include <gtest/gtest.h>

namespace mbslam {
namespace {

struct InnerOptions {
  double rate_hz = 30.0;               // (Hz)
  std::array<double, 3> offset{{0.0, 0.0, 1.5}};  // (m)
  bool Check() const {
    MBSLAM_CHECK_OPTION_GT(rate_hz, 0.0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("rate_hz", &rate_hz, "frame rate (Hz)");
    v("offset", &offset, "offset (m)");
  }
};

struct OuterOptions {
  int max_features = 1000;
  int64_t timeout_us = 2000000;
  float gain = 0.5f;
  bool enabled = true;
  std::string name = "cam0";
  std::vector<double> weights = {1.0, 2.5};
  std::vector<std::string> channels = {"A", "B"};
  InnerOptions inner;
  bool Check() const {
    MBSLAM_CHECK_OPTION_GT(max_features, 0);
    MBSLAM_CHECK_OPTION_SECTION(inner);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("max_features", &max_features, "features (count)");
    v("timeout_us", &timeout_us, "timeout (us)");
    v("gain", &gain, "gain");
    v("enabled", &enabled, "on/off");
    v("name", &name, "camera name");
    v("weights", &weights, "weights");
    v("channels", &channels, "channel names");
    v("inner", &inner, "nested section");
  }
};

static_assert(kIsOptionsStruct<OuterOptions>);
static_assert(!kIsOptionsStruct<int>);

TEST(OptionsYaml, MissingKeysKeepDefaults) {
  OuterOptions options;
  ASSERT_TRUE(LoadOptionsFromYamlText("max_features: 5\ninner: {rate_hz: 10}\n", "", &options).ok());
  EXPECT_EQ(options.max_features, 5);
  EXPECT_DOUBLE_EQ(options.inner.rate_hz, 10.0);
  EXPECT_EQ(options.name, "cam0");
  EXPECT_DOUBLE_EQ(options.inner.offset[2], 1.5);
}

TEST(OptionsYaml, EmptyDocumentKeepsDefaults) {
  OuterOptions options;
  EXPECT_TRUE(LoadOptionsFromYamlText("", "", &options).ok());
  EXPECT_EQ(options.max_features, 1000);
}

TEST(OptionsYaml, UnknownKeyIsAnErrorNamingIt) {
  OuterOptions options;
  const Status s = LoadOptionsFromYamlText("inner: {rate_hz: 10, rat_hz: 3}\n", "", &options);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("inner.rat_hz"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("rate_hz"), std::string::npos) << s.message();
}

TEST(OptionsYaml, WrongTypesAreErrors) {
  OuterOptions o;
  EXPECT_FALSE(LoadOptionsFromYamlText("max_features: many\n", "", &o).ok());
  EXPECT_FALSE(LoadOptionsFromYamlText("max_features: 1.5\n", "", &o).ok());
  EXPECT_FALSE(LoadOptionsFromYamlText("max_features: 99999999999\n", "", &o).ok());
  EXPECT_FALSE(LoadOptionsFromYamlText("enabled: maybe\n", "", &o).ok());
  EXPECT_FALSE(LoadOptionsFromYamlText("weights: 3\n", "", &o).ok());
  EXPECT_FALSE(LoadOptionsFromYamlText("inner: 3\n", "", &o).ok());
  EXPECT_FALSE(LoadOptionsFromYamlText("inner: {offset: [1, 2]}\n", "", &o).ok());
  EXPECT_FALSE(LoadOptionsFromYamlText("gain: .nan\n", "", &o).ok());
  EXPECT_FALSE(LoadOptionsFromYamlText("inner: {rate_hz: .inf}\n", "", &o).ok());
  EXPECT_FALSE(LoadOptionsFromYamlText("max_features: [1\n", "", &o).ok());  // syntax
}

TEST(OptionsYaml, FailedCheckReportsTheCondition) {
  OuterOptions o;
  Status s = LoadOptionsFromYamlText("max_features: -3\n", "", &o);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("max_features > 0"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("-3"), std::string::npos) << s.message();
  EXPECT_EQ(o.max_features, 1000);  // a failed load leaves the options unchanged
  s = LoadOptionsFromYamlText("inner: {rate_hz: 0}\n", "", &o);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("inner: "), std::string::npos) << s.message();
}

TEST(OptionsYaml, WrittenYamlReadsBackIdentically) {
  OuterOptions a;
  a.max_features = 7;
  a.timeout_us = 123456789012;
  a.gain = 0.1f;
  a.enabled = false;
  a.name = "with \"quotes\" and: colon";
  a.weights = {0.1, -3e-7, 12345.678};
  a.channels = {"X Y", "Z"};
  a.inner.rate_hz = 1.0 / 3.0;
  a.inner.offset = {{-1.0, 2.0, 1e10}};
  const std::string text = OptionsToYaml(a);
  OuterOptions b;
  ASSERT_TRUE(LoadOptionsFromYamlText(text, "", &b).ok()) << text;
  EXPECT_EQ(OptionsToYaml(b), text);
  EXPECT_EQ(b.name, a.name);
  EXPECT_EQ(b.inner.rate_hz, a.inner.rate_hz);
  EXPECT_EQ(b.gain, a.gain);
  EXPECT_EQ(b.timeout_us, a.timeout_us);
  EXPECT_NE(text.find("# features (count)"), std::string::npos);
}

// Regression (fuzz_calibration_yaml, issue 9): bytes that are not UTF-8 loaded as they
// were but were written back as U+FFFD, so a config or calibration that loaded did not
// read back the same. Such text is an error naming the line.
TEST(OptionsYaml, TextMustBeUtf8) {
  OuterOptions o;
  EXPECT_TRUE(LoadOptionsFromYamlText("name: \"caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x93\xb7\"\n", "", &o).ok());
  EXPECT_EQ(o.name, "caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x93\xb7");
  for (const std::string& bad : {std::string("max_features: 3\nname: cam\xfe\n"),  // not a lead byte
                                std::string("name: \xc3\n"),                      // cut short
                                std::string("name: \xc0\xaf\n"),                 // overlong '/'
                                std::string("name: \xed\xa0\x80\n"),            // surrogate
                                std::string("name: \xf4\x90\x80\x80\n")}) {    // above U+10FFFF
    OuterOptions x;
    const Status s = LoadOptionsFromYamlText(bad, "", &x);
    EXPECT_FALSE(s.ok()) << bad;
    EXPECT_NE(s.message().find("not UTF-8"), std::string::npos) << s.message();
    EXPECT_EQ(x.name, "cam0");
  }
  EXPECT_NE(CheckYamlTextIsUtf8("a: 1\nb: \xff\n", "f.yaml").message().find("f.yaml: line 2"),
            std::string::npos);
}

// Regression (fuzz_config_yaml, issue 9): a key that is a list or a mapping made the
// loader throw YAML::BadConversion at its caller (perception_service --config).
TEST(OptionsYaml, KeysThatAreNotNamesAreErrors) {
  for (const std::string text : {"? [a, b]\n: 1\n", "{[x]: 1}\n", "inner:\n  ? {k: v}\n  : 2\n"}) {
    OuterOptions o;
    Status s;
    ASSERT_NO_THROW(s = LoadOptionsFromYamlText(text, "", &o)) << text;
    EXPECT_FALSE(s.ok()) << text;
    EXPECT_NE(s.message().find("not a name"), std::string::npos) << s.message();
  }
}

}  // namespace
}  // namespace mbslam
