// The temporary file of an atomic write (io/image_io.cpp): written beside its final name,
// renamed into place when whole, removed otherwise. While one exists its path is kept where
// a signal handler can reach it: remove_temporary_files_now() is async-signal-safe, for the
// CLI's handler of a second SIGINT or SIGTERM (the first one stops the work cooperatively,
// and the destructors remove the files).
//
// A process killed outright (SIGKILL, a preempted machine) cannot remove its temporary. Its
// name says which process on which host wrote it, so a later writer on that host removes it
// once that process is gone (remove_stale_temporaries); a final name only ever appears
// whole, by rename.
#pragma once
#include <cstddef>
#include <string>

namespace abcube {

class TemporaryFile {
 public:
  // Names the temporary for `final_path`: ".STEM.tmpPID-HOST.EXT" in the same folder (the
  // extension kept: OpenImageIO picks the format by it; HOST this machine's name, letters,
  // digits, '-' and '_' kept). Creates nothing.
  explicit TemporaryFile(const std::string& final_path);
  ~TemporaryFile();  // removes the temporary unless it was renamed into place
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;

  const std::string& path() const { return path_; }
  // Renames the temporary to the final path (RuntimeFailure naming it when that fails;
  // the temporary is removed). A stop requested meanwhile (base/parallel.hpp) is honoured
  // first: the temporary is removed and Interrupted thrown, so that an interrupted program
  // leaves no new output.
  void commit();

 private:
  std::string path_, final_path_;
  int slot_ = -1;  // in the signal handler's table, or -1 when the table is full
  bool committed_ = false;
};

// Removes every temporary file that exists now. Async-signal-safe (unlink only).
void remove_temporary_files_now();

// Removes the temporaries in `folder` that processes of this host wrote and that no longer
// run (killed before they could), and returns how many. Those of live processes, and of
// other hosts (a folder shared by a cluster), stay. A folder that cannot be read: 0.
size_t remove_stale_temporaries(const std::string& folder);

}  // namespace abcube
