#pragma once
/// @file torn_tail.h
/// @brief Cutting the torn end off a file that a killed (-9) logger was writing, before a
/// respawned logger continues it (docs/faults.md, "Process faults", logging).
///
/// The logger's files are written through buffers (std::ofstream, stdio) that reach the kernel
/// when full as well as at each flush, at any byte: a kill -9 can leave half a CSV row or half an
/// LCM event at the end. Appending after it would glue the next incarnation's first row onto the
/// torn one (both unreadable), and LCM's log reader stops at a torn event, so every event appended
/// after it would be lost to lcm-logplayer and the project's readers. These functions cut the file
/// back to its last whole row or event. No LCM dependency: the event layout is read directly.

#include <cstdint>
#include <string>

namespace meshnav::logging {

/// Cuts a text file after its last '\n' (a torn last row). Returns the bytes cut: 0 when the file
/// ends with a newline, is empty or does not exist. Throws std::runtime_error naming the file when
/// it cannot be read or cut.
int64_t cutTornLine(const std::string& path);

/// Cuts an LCM event log after its last whole event. An event is: magic 0xEDA1DA01, event number
/// (int64), time stamp (int64), channel length c (int32, 1..255), data length d (int32, ≥ 0), then
/// c + d bytes, all integers big-endian. The file is cut at the first event that is not whole or
/// does not start with the magic (a log a reader would stop at anyway). Returns the bytes cut (0
/// when the log ends with a whole event, is empty or does not exist); throws std::runtime_error
/// naming the file when it cannot be read or cut.
int64_t cutTornLcmLogEvent(const std::string& path);

}  // namespace meshnav::logging
