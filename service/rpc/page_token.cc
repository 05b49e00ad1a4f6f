#include "rpc/page_token.h"

#include <fmt/format.h>
#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>

#include <memory>

#include "store/sha256.h"

namespace seep::service {
namespace {

constexpr std::size_t kFingerprintBytes = 8;
constexpr std::size_t kTokenBytes = 8 + kFingerprintBytes;  // cursor, then fingerprint
constexpr std::string_view kAlphabet =
    "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_";  // base64url

// The cursor with what the request asks for, without its paging: the same filters give the same
// bytes (deterministic serialization sorts map entries). Covering the cursor too makes a token
// with a changed byte fail, rather than page from somewhere else.
std::string Fingerprint(const std::string& cursor_bytes, const google::protobuf::Message& request) {
  std::unique_ptr<google::protobuf::Message> filters(request.New());
  filters->CopyFrom(request);
  const auto* descriptor = filters->GetDescriptor();
  for (const char* paging : {"page_token", "page_size"}) {
    if (const auto* field = descriptor->FindFieldByName(paging)) {
      filters->GetReflection()->ClearField(filters.get(), field);
    }
  }
  std::string bytes;
  {
    google::protobuf::io::StringOutputStream out(&bytes);
    google::protobuf::io::CodedOutputStream coded(&out);
    coded.SetSerializationDeterministic(true);
    filters->SerializeToCodedStream(&coded);
  }
  return Sha256(cursor_bytes + bytes).substr(0, kFingerprintBytes);
}

std::string Base64Url(const std::string& bytes) {
  std::string out;
  std::uint32_t bits = 0;
  int count = 0;
  for (const unsigned char c : bytes) {
    bits = (bits << 8) | c;
    count += 8;
    while (count >= 6) {
      count -= 6;
      out += kAlphabet[(bits >> count) & 0x3f];
    }
  }
  if (count > 0) out += kAlphabet[(bits << (6 - count)) & 0x3f];
  return out;
}

std::optional<std::string> FromBase64Url(const std::string& text) {
  std::string out;
  std::uint32_t bits = 0;
  int count = 0;
  for (const char c : text) {
    const auto value = kAlphabet.find(c);
    if (value == std::string_view::npos) return std::nullopt;
    bits = (bits << 6) | static_cast<std::uint32_t>(value);
    count += 6;
    if (count >= 8) {
      count -= 8;
      out += static_cast<char>((bits >> count) & 0xff);
    }
  }
  return out;
}

}  // namespace

std::string EncodePageToken(std::int64_t cursor, const google::protobuf::Message& request) {
  std::string bytes(8, '\0');
  for (int i = 0; i < 8; ++i) {
    bytes[static_cast<std::size_t>(i)] =
        static_cast<char>((static_cast<std::uint64_t>(cursor) >> (56 - 8 * i)) & 0xff);
  }
  return Base64Url(bytes + Fingerprint(bytes, request));
}

core::Result<std::optional<std::int64_t>> DecodePageToken(const std::string& token,
                                                          const google::protobuf::Message& request,
                                                          const char* rpc) {
  if (token.empty()) return std::optional<std::int64_t>();
  const std::optional<std::string> bytes = FromBase64Url(token);
  if (!bytes || bytes->size() != kTokenBytes || Base64Url(*bytes) != token) {
    return core::InvalidArgument(fmt::format("page_token: not a token returned by {}", rpc));
  }
  if (bytes->substr(8) != Fingerprint(bytes->substr(0, 8), request)) {
    return core::InvalidArgument(fmt::format(
        "page_token: was returned by {} for other filters, or is damaged; a token continues "
        "only the listing it came from (ask again without page_token)",
        rpc));
  }
  std::uint64_t cursor = 0;
  for (int i = 0; i < 8; ++i) {
    cursor = (cursor << 8) | static_cast<unsigned char>((*bytes)[static_cast<std::size_t>(i)]);
  }
  if (static_cast<std::int64_t>(cursor) <= 0) {
    return core::InvalidArgument(fmt::format("page_token: not a token returned by {}", rpc));
  }
  return std::optional<std::int64_t>(static_cast<std::int64_t>(cursor));
}

}  // namespace seep::service
