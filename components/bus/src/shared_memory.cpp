#include "navbus/bus/shared_memory.hpp"

#include <fcntl.h>
#include <semaphore.h>
#include <sys/file.h>
#include <unistd.h>

#include <filesystem>
#include <regex>
#include <system_error>
#include <vector>

namespace navbus::bus {

namespace fs = std::filesystem;

namespace {

struct LockFile {
  fs::path lock;     ///< ..._el or ..._sl
  fs::path target;   ///< the segment or port file it guards
  std::string port;  ///< "fastrtps_port<N>" for a port, empty for a data segment
};

/// True when nobody holds the lock file (its owner is dead); false when it is held or gone.
bool lockIsFree(const fs::path& lock_file) {
  if (lock_file.empty()) return true;  // no lock file at all
  const int fd = ::open(lock_file.c_str(), O_RDONLY);
  if (fd < 0) return false;
  const bool free = ::flock(fd, LOCK_EX | LOCK_NB) == 0;
  ::close(fd);  // releases our lock, if we took it
  return free;
}

bool oldEnough(const LockFile& f, std::chrono::milliseconds min_age) {
  const fs::path& p = f.lock.empty() ? f.target : f.lock;
  std::error_code ec;
  const auto written = fs::last_write_time(p, ec);
  if (ec) return false;
  return fs::file_time_type::clock::now() - written >= min_age;
}

std::uint64_t removeFile(const fs::path& p) {
  if (p.empty()) return 0;
  std::error_code ec;
  const std::uint64_t size = fs::file_size(p, ec);
  if (ec) return 0;
  return fs::remove(p, ec) && !ec ? size : 0;
}

std::vector<LockFile> lockFiles(const std::string& dir) {
  static const std::regex segment_lock("^fastrtps_[0-9a-z]{16}_el$");
  static const std::regex port_lock("^(fastrtps_port[0-9]{1,5})_(el|sl)$");
  static const std::regex port_file("^fastrtps_port[0-9]{1,5}$");
  std::vector<LockFile> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    std::smatch m;
    if (std::regex_match(name, port_file)) {
      // A port whose lock file is gone (an owner killed between removing one and the other):
      // nobody can hold it.
      const fs::path base = e.path();
      if (!fs::exists(base.string() + "_el") && !fs::exists(base.string() + "_sl"))
        out.push_back({{}, base, name});
    } else if (std::regex_match(name, segment_lock)) {
      out.push_back({e.path(), e.path().parent_path() / name.substr(0, name.size() - 3), {}});
    } else if (std::regex_match(name, m, port_lock)) {
      out.push_back({e.path(), e.path().parent_path() / m[1].str(), m[1].str()});
    }
  }
  return out;
}

/// A dead owner's port: removes it (segment, lock file, mutex) under the port's named mutex.
std::uint64_t reclaimPort(const LockFile& f, const fs::path& dir) {
  const std::string sem_name = "/" + f.port + "_mutex";
  sem_t* mutex = ::sem_open(sem_name.c_str(), 0);
  if (mutex == SEM_FAILED) {  // no mutex: nobody can be opening the port right now
    return lockIsFree(f.lock) ? removeFile(f.target) + removeFile(f.lock) : 0;
  }
  std::uint64_t bytes = 0;
  if (::sem_trywait(mutex) == 0) {  // busy: someone opens or closes it now; next time
    if (lockIsFree(f.lock)) {
      bytes = removeFile(f.target) + removeFile(f.lock) +
              removeFile(dir / ("sem." + f.port + "_mutex"));
    }
    ::sem_post(mutex);
  }
  ::sem_close(mutex);
  return bytes;
}

}  // namespace

ShmReclaimResult reclaimSharedMemory(const std::string& dir, std::chrono::milliseconds min_age,
                                     bool reclaim_ports) {
  ShmReclaimResult r;
  for (const LockFile& f : lockFiles(dir)) {
    const bool is_port = !f.port.empty();
    if (is_port && !reclaim_ports) {
      ++(lockIsFree(f.lock) ? r.zombie_ports_left : r.ports_in_use);
      continue;
    }
    if (!oldEnough(f, min_age) || !lockIsFree(f.lock)) {
      ++(is_port ? r.ports_in_use : r.segments_in_use);
      continue;
    }
    const std::uint64_t bytes =
        is_port ? reclaimPort(f, dir) : removeFile(f.target) + removeFile(f.lock);
    if (bytes == 0 && fs::exists(f.target)) continue;
    ++(is_port ? r.zombie_ports : r.zombie_segments);
    r.bytes_reclaimed += bytes;
  }
  return r;
}

bool sharedMemoryInUse(const std::string& dir) {
  for (const LockFile& f : lockFiles(dir)) {
    if (!lockIsFree(f.lock) && fs::exists(f.lock)) return true;
  }
  return false;
}

ShmReclaimResult reclaimIfHostIdle(const std::string& dir) {
  if (sharedMemoryInUse(dir)) return {};
  return reclaimSharedMemory(dir, std::chrono::seconds(1), true);
}

std::uint64_t zombieSharedMemoryBytes(const std::string& dir, bool ports) {
  std::uint64_t bytes = 0;
  for (const LockFile& f : lockFiles(dir)) {
    if (f.port.empty() == ports || !lockIsFree(f.lock)) continue;
    std::error_code ec;
    const std::uint64_t size = fs::file_size(f.target, ec);
    if (!ec) bytes += size;
  }
  return bytes;
}

}  // namespace navbus::bus
