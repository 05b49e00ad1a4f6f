// Page tokens of the list calls: opaque to clients, and bound to the filters of the call that
// returned them. A token carries the store's cursor and a fingerprint of the cursor and of the
// request with its paging fields (page_token, page_size) cleared; a token reused with other
// filters would page through another listing from a cursor that means nothing there, and a
// damaged one from anywhere, so both are refused.
#pragma once

#include <google/protobuf/message.h>

#include <cstdint>
#include <optional>
#include <string>

#include "seep/core/status.h"

namespace seep::service {

// The token that continues `request`'s listing at `cursor`.
std::string EncodePageToken(std::int64_t cursor, const google::protobuf::Message& request);

// The cursor in request.page_token (nullopt when empty: the first page). INVALID_ARGUMENT naming
// page_token when it is not a token `rpc` returned, or was returned for other filters.
core::Result<std::optional<std::int64_t>> DecodePageToken(const std::string& token,
                                                          const google::protobuf::Message& request,
                                                          const char* rpc);

}  // namespace seep::service
