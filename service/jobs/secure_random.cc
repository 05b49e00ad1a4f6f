#include "jobs/secure_random.h"

#include <fcntl.h>
#include <sys/random.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

namespace seep::service {
namespace {

// Fills `out` from /dev/urandom; false on failure (errno set).
bool ReadUrandom(unsigned char* out, std::size_t size) {
  const int fd = ::open("/dev/urandom", O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::read(fd, out + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += static_cast<std::size_t>(n);
  }
  ::close(fd);
  return done == size;
}

}  // namespace

core::Result<std::uint64_t> SecureRandomU64() {
  unsigned char bytes[sizeof(std::uint64_t)];
  std::size_t done = 0;
  while (done < sizeof bytes) {
    const ssize_t n = ::getrandom(bytes + done, sizeof bytes - done, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += static_cast<std::size_t>(n);
  }
  if (done != sizeof bytes && !ReadUrandom(bytes, sizeof bytes)) {
    return core::Unavailable(std::string("random: neither getrandom(2) nor /dev/urandom: ") +
                             std::strerror(errno));
  }
  std::uint64_t value = 0;
  std::memcpy(&value, bytes, sizeof value);
  return value;
}

}  // namespace seep::service
