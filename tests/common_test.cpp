#include <gtest/gtest.h>

#include <vector>

#include "common/progress.h"
#include "common/status.h"

namespace mm {

TEST(Status, DefaultIsOkAndNamesAreStable) {
  Status s;
  EXPECT_TRUE(s.ok());
  EXPECT_STREQ(status_code_name(StatusCode::InvalidMesh), "InvalidMesh");
  EXPECT_STREQ(status_code_name(StatusCode::Cancelled), "Cancelled");
  const Status e = Status::error(StatusCode::ParseError, "bad");
  EXPECT_FALSE(e.ok());
  EXPECT_EQ(e.message, "bad");
}

TEST(Progress, NoopSinkNeverCancels) {
  Progress p;
  EXPECT_TRUE(p.update("x", 0.5));
  EXPECT_FALSE(p.cancelled());
}

TEST(Progress, SubRangesMapIntoParentAndShareCancel) {
  std::vector<double> seen;
  int calls = 0;
  Progress p([&](const std::string&, double f) {
    seen.push_back(f);
    return ++calls < 3;
  });
  const Progress a = p.sub(0.2, 0.6);
  const Progress b = a.sub(0.5, 1.0);  // 0.4 .. 0.6 overall
  EXPECT_TRUE(a.update("a", 0.5));
  EXPECT_TRUE(b.update("b", 0.5));
  EXPECT_FALSE(b.update("b", 1.0));  // third call: callback asks to cancel
  EXPECT_TRUE(p.cancelled());
  EXPECT_FALSE(a.update("a", 1.0));  // cancel is shared, callback not called again
  ASSERT_EQ(seen.size(), 3u);
  EXPECT_NEAR(seen[0], 0.4, 1e-12);
  EXPECT_NEAR(seen[1], 0.5, 1e-12);
  EXPECT_NEAR(seen[2], 0.6, 1e-12);
  EXPECT_EQ(cancelled_status("factor").code, StatusCode::Cancelled);
}

TEST(Progress, FractionIsClamped) {
  double last = -1;
  Progress p([&](const std::string&, double f) {
    last = f;
    return true;
  });
  p.update("x", 7.0);
  EXPECT_EQ(last, 1.0);
  p.update("x", -1.0);
  EXPECT_EQ(last, 0.0);
}

}  // namespace mm
