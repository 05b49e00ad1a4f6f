#include "checkpoint_io.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <google/protobuf/util/delimited_message_util.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "seep/v1/checkpoint.pb.h"

namespace seep::service {
namespace {

constexpr std::string_view kMagic = "SEEPCKPT";

using core::DataLoss;
using core::Status;

Status ErrnoStatus(const std::string& what, const std::filesystem::path& path) {
  return core::Unavailable(
      fmt::format("checkpoint: {} {}: {}", what, path.string(), std::strerror(errno)));
}

void AppendDelimited(const google::protobuf::MessageLite& message, std::string* out) {
  google::protobuf::io::StringOutputStream stream(out);
  google::protobuf::util::SerializeDelimitedToZeroCopyStream(message, &stream);
}

// Writes all bytes to a new file and fsyncs it.
Status WriteAndSync(const std::filesystem::path& path, std::string_view bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return ErrnoStatus("cannot create", path);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      Status s = ErrnoStatus("cannot write", path);
      ::close(fd);
      return s;
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    Status s = ErrnoStatus("cannot fsync", path);
    ::close(fd);
    return s;
  }
  if (::close(fd) != 0) return ErrnoStatus("cannot close", path);
  return Status::Ok();
}

Status SyncDirectory(const std::filesystem::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return ErrnoStatus("cannot open directory", dir);
  const int rc = ::fsync(fd);
  ::close(fd);
  if (rc != 0) return ErrnoStatus("cannot fsync directory", dir);
  return Status::Ok();
}

}  // namespace

Status WriteCheckpointFile(const std::filesystem::path& path, const CheckpointMeta& meta,
                           std::string_view state) {
  v1::CheckpointHeader header;
  header.set_format_version(meta.format_version);
  header.set_build_id(meta.build_id);
  header.set_job_id(meta.job_id);
  header.set_scene_sha256(meta.scene_sha256);
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

  std::filesystem::path tmp = path;
  tmp += ".tmp";
  SEEP_RETURN_IF_ERROR(WriteAndSync(tmp, bytes));
  if (::rename(tmp.c_str(), path.c_str()) != 0) return ErrnoStatus("cannot rename onto", path);
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : ".";
  return SyncDirectory(dir);
}

core::Result<CheckpointFile> ReadCheckpointFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return core::NotFound(fmt::format("checkpoint: {}: cannot open", path.string()));
  std::ostringstream buffer;
  buffer << in.rdbuf();
  const std::string bytes = buffer.str();
  const std::string name = path.filename().string();
  auto loss = [&](const std::string& why) {
    return DataLoss(fmt::format("checkpoint: {}: {}", name, why));
  };
  if (bytes.compare(0, kMagic.size(), kMagic) != 0) return loss("not a seep checkpoint (magic)");

  google::protobuf::io::ArrayInputStream stream(bytes.data() + kMagic.size(),
                                                static_cast<int>(bytes.size() - kMagic.size()));
  bool clean_eof = false;
  v1::CheckpointHeader header;
  if (!google::protobuf::util::ParseDelimitedFromZeroCopyStream(&header, &stream, &clean_eof)) {
    return loss("truncated or corrupt header");
  }
  if (header.format_version() < 1 || header.format_version() > kCheckpointFormatVersion) {
    return core::FailedPrecondition(
        fmt::format("checkpoint: {}: format version {} is not readable by this build (1..{})", name,
                    header.format_version(), kCheckpointFormatVersion));
  }
  CheckpointFile file;
  file.meta = {header.format_version(), header.build_id(), header.job_id(),
               header.scene_sha256(),   header.step(),     header.time_s()};
  file.state.reserve(header.state_bytes());
  for (std::uint32_t c = 0; c < header.chunk_count(); ++c) {
    v1::CheckpointChunk chunk;
    if (!google::protobuf::util::ParseDelimitedFromZeroCopyStream(&chunk, &stream, &clean_eof)) {
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
  const auto before_trailer = static_cast<std::size_t>(stream.ByteCount()) + kMagic.size();
  v1::CheckpointTrailer trailer;
  if (!google::protobuf::util::ParseDelimitedFromZeroCopyStream(&trailer, &stream, &clean_eof)) {
    return loss("truncated before the trailer");
  }
  if (trailer.file_sha256() != Sha256(std::string_view(bytes).substr(0, before_trailer))) {
    return loss("file checksum mismatch");
  }
  if (static_cast<std::size_t>(stream.ByteCount()) + kMagic.size() != bytes.size()) {
    return loss("unexpected bytes after the trailer");
  }
  return file;
}

}  // namespace seep::service
