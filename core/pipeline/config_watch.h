// Watching the configuration file (`watch: true`): rank 0 looks at the file on the steps the
// configuration schedules and, when its contents changed, hands the new text to every rank, so
// that all ranks switch at the same step.
//
// Cheap on purpose: one stat() on rank 0 and one broadcast of a length per check; the file is
// read (and hashed) only when its modification time, size or inode changed, and the text is
// broadcast only when its hash differs from the last text seen. A file that cannot be read is
// reported once (until it can be read again); the caller keeps its configuration meanwhile.
//
// Ownership: plain value (the path and what rank 0 last saw). Thread-safety: one thread.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <string>

namespace lantern {

class ConfigWatch {
 public:
  // Watches `path`, whose text the running configuration was made from has hash `text_hash`.
  // Keeps what rank 0 saw of the file when the path is the one already watched.
  void start(const std::string &path, uint64_t text_hash);
  void stop() { path_.clear(); }
  bool active() const { return !path_.empty(); }
  const std::string &path() const { return path_; }

  // Collective (on every rank at the same step). Returns true, with the file's new text in
  // *text on every rank, when the contents changed since the last look. On rank 0, *problem gets
  // a message the first time the file cannot be read (stat or read failed), else stays empty.
  bool poll(MPI_Comm comm, std::string *text, std::string *problem);

 private:
  // Rank 0: the new text when the contents changed, else false; a read failure in *problem.
  bool look(std::string *text, std::string *problem);

  std::string path_;
  uint64_t seen_hash_ = 0;  // hash of the last text seen (applied or not)
  // What stat() said last time (rank 0); a change of any of them means "read the file again".
  int64_t mtime_ns_ = -1, size_ = -1;
  uint64_t inode_ = 0;
  std::string reported_;  // the problem already reported ("" when the file was readable)
};

}  // namespace lantern
