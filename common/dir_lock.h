#pragma once
/// @file dir_lock.h
/// @brief An exclusive claim on a folder a process writes into (the logger's --out, the
/// estimator's and the calibrator's --state-dir): a second process given the same folder — a
/// second launch of the same launch file, even in another network namespace where the LCM
/// publisher check cannot hear it — is refused instead of writing into the first one's files.
///
/// The claim is flock(LOCK_EX) on `<folder>/.lock`, held while the DirLock lives. The kernel drops
/// it when the process ends, however it ends (kill -9 included), so a respawned process gets the
/// folder back at once; the file's content, the holder's pid, only serves the message.

#include <stdexcept>
#include <string>

namespace meshnav {

/// Thrown when another process holds the folder: transport::ProcessMain ends the process with
/// kExitSecondInstance (7), as for another instance heard on LCM.
class DirLockError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class DirLock {
 public:
  /// Creates `dir` if needed and claims it for this process. `what` names the folder's role in
  /// the message ("--out"). Throws DirLockError naming the folder and the holder's pid when
  /// another process holds it, std::runtime_error when the lock file cannot be made.
  DirLock(const std::string& dir, const std::string& what);
  ~DirLock();
  DirLock(const DirLock&) = delete;
  DirLock& operator=(const DirLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace meshnav
