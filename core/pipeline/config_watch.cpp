#include "core/pipeline/config_watch.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

#include "core/common/content_hash.h"
#include "core/config/config_file.h"

namespace lantern {

void ConfigWatch::start(const std::string &path, uint64_t text_hash) {
  if (path != path_) {
    mtime_ns_ = size_ = -1;
    inode_ = 0;
    reported_.clear();
  }
  path_ = path;
  seen_hash_ = text_hash;
}

bool ConfigWatch::look(std::string *text, std::string *problem) {
  const auto unreadable = [&](const std::string &why) {
    const std::string message = "config file '" + path_ + "' " + why +
                                "; keeping the last good configuration (watch: true)";
    if (message != reported_) *problem = reported_ = message;
    mtime_ns_ = size_ = -1;  // read it again once it is back
    return false;
  };
  struct stat st {};
  if (::stat(path_.c_str(), &st) != 0)
    return unreadable(std::string("cannot be read: ") + std::strerror(errno));
  const int64_t mtime = int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec;
  if (mtime == mtime_ns_ && int64_t(st.st_size) == size_ && uint64_t(st.st_ino) == inode_)
    return false;
  std::string read;
  if (const std::string why = read_config_file(path_, &read); !why.empty())
    return unreadable((why.rfind("is ", 0) == 0 ? "" : "cannot be read: ") + why);
  // An editor that truncates, then writes, can be caught in between; an empty configuration is
  // never valid, so it is not applied (and it is read again at the next look).
  if (read.empty()) return unreadable("is empty");
  mtime_ns_ = mtime, size_ = int64_t(st.st_size), inode_ = uint64_t(st.st_ino);
  reported_.clear();
  *text = std::move(read);
  const uint64_t hash = content_hash(*text);
  if (hash == seen_hash_) return false;  // touched or rewritten with the same text
  seen_hash_ = hash;
  return true;
}

bool ConfigWatch::poll(MPI_Comm comm, std::string *text, std::string *problem) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  int64_t length = -1;  // -1: no new text
  if (rank == 0 && look(text, problem)) length = int64_t(text->size());
  MPI_Bcast(&length, 1, MPI_INT64_T, 0, comm);
  if (length < 0) return false;
  text->resize(size_t(length));
  // Configuration files are small; one broadcast carries the whole text.
  MPI_Bcast(text->data(), int(length), MPI_CHAR, 0, comm);
  const uint64_t hash = content_hash(*text);
  seen_hash_ = hash;  // every rank remembers it, should rank 0 change later
  return true;
}

}  // namespace lantern
