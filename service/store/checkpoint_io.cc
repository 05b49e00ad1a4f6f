#include "checkpoint_io.h"

#include <fmt/format.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <google/protobuf/util/delimited_message_util.h>

#include <fstream>
#include <sstream>

#include "durable_files.h"
#include "seep/v1/checkpoint.pb.h"

namespace seep::service {
namespace {

constexpr std::string_view kMagic = "SEEPCKPT";

using core::DataLoss;
using core::Status;

void AppendDelimited(const google::protobuf::MessageLite& message, std::string* out) {
  google::protobuf::io::StringOutputStream stream(out);
  google::protobuf::util::SerializeDelimitedToZeroCopyStream(message, &stream);
}

// Length-delimited messages read from a byte string at 64-bit offsets: protobuf's own streams
// count in int and stop at 2 GiB, a checkpoint file need not. Each message (a header, a chunk of
// at most kCheckpointChunkBytes, a trailer) is small.
class DelimitedReader {
 public:
  DelimitedReader(std::string_view bytes, std::size_t offset) : bytes_(bytes), offset_(offset) {}

  // False when the bytes end or do not hold a whole, parsable message.
  bool Next(google::protobuf::MessageLite* message) {
    std::uint64_t length = 0;
    for (int shift = 0;; shift += 7) {
      if (offset_ >= bytes_.size() || shift > 28) return false;
      const auto byte = static_cast<unsigned char>(bytes_[offset_++]);
      length |= static_cast<std::uint64_t>(byte & 0x7f) << shift;
      if ((byte & 0x80) == 0) break;
    }
    if (length > bytes_.size() - offset_) return false;
    const bool parsed = message->ParseFromArray(bytes_.data() + offset_, static_cast<int>(length));
    offset_ += static_cast<std::size_t>(length);
    return parsed;
  }
  std::size_t offset() const { return offset_; }

 private:
  std::string_view bytes_;
  std::size_t offset_;
};

}  // namespace

std::string EncodeCheckpoint(const CheckpointMeta& meta, std::string_view state) {
  v1::CheckpointHeader header;
  header.set_format_version(meta.format_version);
  header.set_build_id(meta.build_id);
  header.set_job_id(meta.job_id);
  header.set_scene_sha256(meta.scene_sha256);
  header.set_scene(meta.scene);
  header.set_step(meta.step);
  header.set_time_s(meta.time_s);
  const std::size_t chunks = (state.size() + kCheckpointChunkBytes - 1) / kCheckpointChunkBytes;
  header.set_chunk_count(static_cast<std::uint32_t>(chunks));
  header.set_state_bytes(state.size());

  std::string bytes(kMagic);
  AppendDelimited(header, &bytes);
  for (std::size_t c = 0; c < chunks; ++c) {
    v1::CheckpointChunk chunk;
    chunk.set_index(static_cast<std::uint32_t>(c));
    const std::string_view payload = state.substr(c * kCheckpointChunkBytes, kCheckpointChunkBytes);
    chunk.set_payload(std::string(payload));
    chunk.set_sha256(Sha256(payload));
    AppendDelimited(chunk, &bytes);
  }
  v1::CheckpointTrailer trailer;
  trailer.set_file_sha256(Sha256(bytes));
  AppendDelimited(trailer, &bytes);
  return bytes;
}

std::string HideDataFolder(std::string message, const std::filesystem::path& checkpoint_path) {
  const std::string folder = checkpoint_path.parent_path().parent_path().parent_path().string();
  if (folder.empty() || folder == "/") return message;
  const std::string prefix = folder.back() == '/' ? folder : folder + "/";
  for (auto at = message.find(prefix); at != std::string::npos; at = message.find(prefix, at)) {
    message.erase(at, prefix.size());
  }
  return message;
}

Status WriteCheckpointBytes(const std::filesystem::path& path, std::string_view bytes) {
  if (Status s = WriteFileDurably(path, bytes); !s.ok()) {
    return {s.code(), "checkpoint: " + HideDataFolder(s.message(), path)};
  }
  return Status::Ok();
}

Status WriteCheckpointFile(const std::filesystem::path& path, const CheckpointMeta& meta,
                           std::string_view state) {
  return WriteCheckpointBytes(path, EncodeCheckpoint(meta, state));
}

core::Result<CheckpointFile> DecodeCheckpoint(std::string_view bytes, std::string_view name) {
  auto loss = [&](const std::string& why) {
    return DataLoss(fmt::format("checkpoint: {}: {}", name, why));
  };
  if (bytes.substr(0, kMagic.size()) != kMagic) return loss("not a seep checkpoint (magic)");

  DelimitedReader reader(bytes, kMagic.size());
  v1::CheckpointHeader header;
  if (!reader.Next(&header)) {
    return loss("truncated or corrupt header");
  }
  if (header.format_version() < 1 || header.format_version() > kCheckpointFormatVersion) {
    return core::FailedPrecondition(
        fmt::format("checkpoint: {}: format version {} is not readable by this build (1..{})", name,
                    header.format_version(), kCheckpointFormatVersion));
  }
  CheckpointFile file;
  file.meta.format_version = header.format_version();
  file.meta.build_id = header.build_id();
  file.meta.job_id = header.job_id();
  file.meta.scene_sha256 = header.scene_sha256();
  file.meta.scene = header.scene();
  file.meta.step = header.step();
  file.meta.time_s = header.time_s();
  if (!file.meta.scene.empty() && Sha256(file.meta.scene) != file.meta.scene_sha256) {
    return loss("its scene does not have the scene's SHA-256 in its header");
  }
  file.state.reserve(header.state_bytes());
  for (std::uint32_t c = 0; c < header.chunk_count(); ++c) {
    v1::CheckpointChunk chunk;
    if (!reader.Next(&chunk)) {
      return loss(fmt::format("truncated at chunk {} of {}", c, header.chunk_count()));
    }
    if (chunk.index() != c || chunk.sha256() != Sha256(chunk.payload())) {
      return loss(fmt::format("chunk {} fails its checksum", c));
    }
    file.state += chunk.payload();
  }
  if (file.state.size() != header.state_bytes()) {
    return loss(
        fmt::format("state has {} bytes, header says {}", file.state.size(), header.state_bytes()));
  }
  const std::size_t before_trailer = reader.offset();
  v1::CheckpointTrailer trailer;
  if (!reader.Next(&trailer)) {
    return loss("truncated before the trailer");
  }
  if (trailer.file_sha256() != Sha256(bytes.substr(0, before_trailer))) {
    return loss("file checksum mismatch");
  }
  if (reader.offset() != bytes.size()) {
    return loss("unexpected bytes after the trailer");
  }
  return file;
}

core::Result<CheckpointFile> ReadCheckpointFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return core::NotFound(
        fmt::format("checkpoint: {}: cannot open", HideDataFolder(path.string(), path)));
  }
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return DecodeCheckpoint(buffer.str(), path.filename().string());
}

core::Result<CheckpointFile> ReadCheckpoint(const CheckpointRecord& record) {
  if (record.path.empty()) return DecodeCheckpoint(record.content, CheckpointName(record));
  return ReadCheckpointFile(record.path);
}

std::string CheckpointName(const CheckpointRecord& record) {
  if (record.path.empty()) return fmt::format("ckpt-{:012}.bin (in the store)", record.step);
  return std::filesystem::path(record.path).filename().string();
}

}  // namespace seep::service
