#include "durable_files.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <vector>

namespace seep::service {
namespace {

using core::Status;

// A full disk (or quota) is RESOURCE_EXHAUSTED: a running job's checkpoint that meets one stops
// the job with the reason (jobs/job_runner.h) instead of being retried as a passing failure.
Status ErrnoStatus(const std::string& what, const std::filesystem::path& path) {
  const int error = errno;
  const auto code = error == ENOSPC || error == EDQUOT ? core::StatusCode::kResourceExhausted
                                                       : core::StatusCode::kUnavailable;
  return {code, fmt::format("{} {}: {}", what, path.string(), std::strerror(error))};
}

std::filesystem::path ParentOf(const std::filesystem::path& path) {
  return path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
}

Status SyncDirectory(const std::filesystem::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return ErrnoStatus("cannot open directory", dir);
  const int rc = ::fsync(fd);
  ::close(fd);
  if (rc != 0) return ErrnoStatus("cannot fsync directory", dir);
  return Status::Ok();
}

Status WriteAll(int fd, std::string_view bytes, const std::filesystem::path& path) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return ErrnoStatus("cannot write", path);
    done += static_cast<std::size_t>(n);
  }
  return Status::Ok();
}

}  // namespace

bool IsTempFileName(std::string_view file_name) {
  return file_name.find(kTempFileMarker) != std::string_view::npos;
}

Status CreateDirectoriesDurably(const std::filesystem::path& dir) {
  // The missing folders, outermost first.
  std::vector<std::filesystem::path> missing;
  for (std::filesystem::path p = dir.lexically_normal(); !p.empty();) {
    std::error_code ec;
    if (std::filesystem::is_directory(p, ec)) break;
    missing.push_back(p);
    if (!p.has_parent_path() || p.parent_path() == p) break;
    p = p.parent_path();
  }
  for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
    if (::mkdir(it->c_str(), 0700) != 0 && errno != EEXIST) {
      return ErrnoStatus("cannot create directory", *it);
    }
    SEEP_RETURN_IF_ERROR(SyncDirectory(ParentOf(*it)));
  }
  return Status::Ok();
}

Status WriteFileDurably(const std::filesystem::path& path, std::string_view bytes) {
  // mkstemp: a name no other writer holds, created 0600 with O_EXCL.
  std::string tmp = path.string() + std::string(kTempFileMarker) + "XXXXXX";
  const int fd = ::mkostemp(tmp.data(), O_CLOEXEC);
  if (fd < 0) return ErrnoStatus("cannot create a temporary file beside", path);
  const auto fail = [&](Status s) {
    ::close(fd);
    ::unlink(tmp.c_str());
    return s;
  };
  if (Status s = WriteAll(fd, bytes, tmp); !s.ok()) return fail(s);
  if (::fsync(fd) != 0) return fail(ErrnoStatus("cannot fsync", tmp));
  if (::close(fd) != 0) {
    ::unlink(tmp.c_str());
    return ErrnoStatus("cannot close", tmp);
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    Status s = ErrnoStatus("cannot rename onto", path);
    ::unlink(tmp.c_str());
    return s;
  }
  return SyncDirectory(ParentOf(path));
}

Status RemoveDurably(const std::filesystem::path& path) {
  if (::remove(path.c_str()) != 0) {
    if (errno == ENOENT) return Status::Ok();
    return ErrnoStatus("cannot remove", path);
  }
  return SyncDirectory(ParentOf(path));
}

}  // namespace seep::service
