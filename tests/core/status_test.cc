#include "seep/core/status.h"

#include <gtest/gtest.h>

namespace seep::core {
namespace {

Result<int> ParsePositive(int v) {
  if (v <= 0) return InvalidArgument("value: must be > 0 (got " + std::to_string(v) + ")");
  return v;
}

Result<int> Doubled(int v) {
  SEEP_ASSIGN_OR_RETURN(int x, ParsePositive(v));
  return 2 * x;
}

Status Check(int v) {
  SEEP_RETURN_IF_ERROR(ParsePositive(v).status());
  return Status::Ok();
}

TEST(Status, CarriesCodeAndMessage) {
  const Status s = InvalidArgument("scene.fluid.viscosity: must be > 0");
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(s.ToString(), "INVALID_ARGUMENT: scene.fluid.viscosity: must be > 0");
  EXPECT_EQ(Status::Ok().ToString(), "OK");
}

TEST(Status, AssignOrReturnPropagates) {
  ASSERT_TRUE(Doubled(4).ok());
  EXPECT_EQ(*Doubled(4), 8);
  const Result<int> bad = Doubled(-1);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().message(), "value: must be > 0 (got -1)");
  EXPECT_TRUE(Check(3).ok());
  EXPECT_EQ(Check(0).code(), StatusCode::kInvalidArgument);
}

TEST(Status, ResultFromOkStatusIsAnInternalError) {
  const Result<int> r(Status::Ok());
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInternal);
}

}  // namespace
}  // namespace seep::core
