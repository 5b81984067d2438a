#include "dyncull/culling/labels.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace {
using namespace dyncull;

TEST(Labels, ValuesAreStableForSerialisation) {
  EXPECT_EQ(static_cast<int>(FeatureLabel::Static), 0);
  EXPECT_EQ(static_cast<int>(FeatureLabel::Candidate), 1);
  EXPECT_EQ(static_cast<int>(FeatureLabel::Dynamic), 2);
  EXPECT_EQ(static_cast<int>(CullReason::None), 0);
}

TEST(Labels, EveryValueHasADistinctName) {
  std::set<std::string> names;
  for (FeatureLabel l : {FeatureLabel::Static, FeatureLabel::Candidate, FeatureLabel::Dynamic}) {
    EXPECT_STRNE(to_string(l), "unknown");
    names.insert(to_string(l));
  }
  EXPECT_EQ(names.size(), 3u);
  names.clear();
  const int last = static_cast<int>(CullReason::ListedStage);
  for (int r = 0; r <= last; ++r) {
    const char* s = to_string(static_cast<CullReason>(r));
    EXPECT_STRNE(s, "unknown") << r;
    names.insert(s);
  }
  EXPECT_EQ(names.size(), static_cast<std::size_t>(last + 1));
  EXPECT_STREQ(to_string(static_cast<CullReason>(last + 1)), "unknown");
}

TEST(Labels, MaxLabelOrdersBySeverity) {
  EXPECT_EQ(max_label(FeatureLabel::Static, FeatureLabel::Candidate), FeatureLabel::Candidate);
  EXPECT_EQ(max_label(FeatureLabel::Dynamic, FeatureLabel::Candidate), FeatureLabel::Dynamic);
  EXPECT_EQ(max_label(FeatureLabel::Static, FeatureLabel::Static), FeatureLabel::Static);
  static_assert(max_label(FeatureLabel::Candidate, FeatureLabel::Dynamic) == FeatureLabel::Dynamic, "constexpr");
}
}  // namespace
