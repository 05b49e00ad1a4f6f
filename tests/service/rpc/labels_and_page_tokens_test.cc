// The request checks of the operations calls: labels (SubmitJob, ListJobs) and page tokens bound
// to their filters (ListJobs, ListCalibrations, ListJobEvents).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <functional>
#include <map>
#include <string>

#include "rpc/job_labels.h"
#include "rpc/page_token.h"
#include "seep/v1/job_service.pb.h"

// GCC 12 reports a false -Wrestrict inside std::string's copy when keys built in a loop are
// inserted into a map (GCC bug 105329); nothing here overlaps.
#pragma GCC diagnostic ignored "-Wrestrict"

namespace seep::service {
namespace {

std::string LabelError(const std::map<std::string, std::string>& labels) {
  v1::SubmitJobRequest request;
  for (const auto& [k, v] : labels) (*request.mutable_labels())[k] = v;
  const auto checked = CheckLabels(request.labels());
  EXPECT_FALSE(checked.ok());
  if (checked.ok()) return {};
  EXPECT_EQ(checked.status().code(), core::StatusCode::kInvalidArgument);
  return checked.status().message();
}

TEST(Labels, GoodOnesComeBackSortedByKey) {
  v1::SubmitJobRequest request;
  (*request.mutable_labels())["team"] = "flow";
  (*request.mutable_labels())["a.b-c_9"] = "";
  (*request.mutable_labels())["owner"] = "ana.b@lab:2/x+y";
  const auto checked = CheckLabels(request.labels());
  ASSERT_TRUE(checked.ok()) << checked.status().ToString();
  EXPECT_EQ(*checked, (std::vector<std::pair<std::string, std::string>>{
                          {"a.b-c_9", ""}, {"owner", "ana.b@lab:2/x+y"}, {"team", "flow"}}));
  v1::SubmitJobRequest many;
  for (std::size_t i = 0; i < kMaxLabels; ++i)
    (*many.mutable_labels())[fmt::format("k{}", i)] = "v";
  EXPECT_TRUE(CheckLabels(many.labels()).ok());
}

TEST(Labels, ABadOneIsNamedWithTheReason) {
  EXPECT_EQ(LabelError({{"Team", "x"}}).rfind("labels[\"Team\"]: the key must be lower-case", 0),
            0u);
  EXPECT_NE(LabelError({{"9lives", "x"}}).find("starting with a letter"), std::string::npos);
  EXPECT_NE(LabelError({{"team-", "x"}}).find("ending with a letter or digit"), std::string::npos);
  EXPECT_EQ(LabelError({{"", "x"}}), "labels[\"\"]: the key must hold 1 to 63 characters (got 0)");
  EXPECT_NE(LabelError({{std::string(64, 'a'), "x"}}).find("1 to 63 characters (got 64)"),
            std::string::npos);
  EXPECT_EQ(LabelError({{"owner", "a b"}}),
            "labels[\"owner\"]: the value 'a b' may hold only letters, digits and - _ . : / @ +");
  EXPECT_NE(LabelError({{"owner", std::string(129, 'v')}}).find("at most 128 characters (got 129)"),
            std::string::npos);
  // A control character is shown escaped, not printed raw.
  EXPECT_EQ(LabelError({{"a\nb", "x"}}).rfind("labels[\"a\\x0ab\"]", 0), 0u);
  std::map<std::string, std::string> too_many;
  for (std::size_t i = 0; i <= kMaxLabels; ++i) too_many[fmt::format("k{}", i)] = "v";
  EXPECT_EQ(LabelError(too_many), "labels: at most 32 per job (got 33)");
}

TEST(PageTokens, RoundTripWithTheSameFiltersWhateverThePageSize) {
  v1::ListJobsRequest request;
  request.set_name_contains("darcy");
  (*request.mutable_labels())["team"] = "flow";
  (*request.mutable_labels())["owner"] = "ana";
  const std::string token = EncodePageToken(123456789012345, request);
  EXPECT_EQ(
      token.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_"),
      std::string::npos);
  request.set_page_token(token);
  request.set_page_size(7);
  const auto cursor = DecodePageToken(token, request, "ListJobs");
  ASSERT_TRUE(cursor.ok()) << cursor.status().ToString();
  EXPECT_EQ(*cursor, std::optional<std::int64_t>(123456789012345));
  EXPECT_EQ(*DecodePageToken("", request, "ListJobs"), std::nullopt);
}

TEST(PageTokens, OtherFiltersOrAForgedTokenAreRefused) {
  v1::ListJobsRequest request;
  request.add_states(v1::JOB_STATE_RUNNING);
  const std::string token = EncodePageToken(40, request);
  for (const auto& change : std::vector<std::function<void(v1::ListJobsRequest&)>>{
           [](v1::ListJobsRequest& r) { r.add_states(v1::JOB_STATE_QUEUED); },
           [](v1::ListJobsRequest& r) { r.set_name_contains("x"); },
           [](v1::ListJobsRequest& r) { r.add_kinds(v1::JOB_KIND_CALIBRATION); },
           [](v1::ListJobsRequest& r) { (*r.mutable_labels())["a"] = "b"; },
       }) {
    v1::ListJobsRequest other = request;
    change(other);
    const auto refused = DecodePageToken(token, other, "ListJobs");
    EXPECT_EQ(refused.status().code(), core::StatusCode::kInvalidArgument);
    EXPECT_EQ(refused.status().message().rfind(
                  "page_token: was returned by ListJobs for other filters", 0),
              0u)
        << refused.status().message();
  }
  std::string flipped = token;
  flipped[0] = flipped[0] == 'A' ? 'B' : 'A';
  for (const std::string& forged :
       {std::string("40"), fmt::format("{}A", token), flipped, std::string("!!")}) {
    const auto refused = DecodePageToken(forged, request, "ListJobs");
    EXPECT_EQ(refused.status().code(), core::StatusCode::kInvalidArgument) << forged;
  }
  EXPECT_NE(DecodePageToken(flipped, request, "ListJobs").status().message().find("or is damaged"),
            std::string::npos);
  EXPECT_EQ(DecodePageToken("40", request, "ListJobs").status().message(),
            "page_token: not a token returned by ListJobs");
  // A token of one job's events does not page another job's.
  v1::ListJobEventsRequest events;
  events.set_id("j-1");
  const std::string events_token = EncodePageToken(5, events);
  events.set_id("j-2");
  EXPECT_FALSE(DecodePageToken(events_token, events, "ListJobEvents").ok());
}

}  // namespace
}  // namespace seep::service
