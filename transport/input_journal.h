#pragma once
/// @file input_journal.h
/// @brief An append-only journal of the inputs a process consumed, so that a restarted process
/// (respawned after a crash, even kill -9) gets back what it had collected by replaying them
/// (the calibrator: `--state-dir`, docs/faults.md "Process faults").
///
/// The file is an LCM event log (lcm-logplayer and lcm-spy read it): every input is written as
/// the LCM message of its channel and flushed to the kernel at once (`fflush` per event), so a
/// kill -9 loses nothing that was written; a power cut may lose what the kernel had not written
/// yet (no fsync). A truncated last event is skipped when read.

#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "common/diagnostics.h"
#include "transport/channels.h"
#include "transport/convert.h"
#include "transport/wire_versions.h"

namespace meshnav::transport {

class InputJournal {
 public:
  /// Opens (creates) `path` for appending; creates its folder. Throws std::runtime_error.
  explicit InputJournal(std::string path);
  ~InputJournal();
  InputJournal(const InputJournal&) = delete;
  InputJournal& operator=(const InputJournal&) = delete;

  /// Appends `value` (of the channel's type) as its LCM message on `channel`, stamped `utime`.
  template <class T>
  void write(channels::Channel<T> channel, const std::type_identity_t<T>& value, int64_t utime) {
    writeAs<T>("", channel, value, utime);
  }
  /// The same on vehicle `prefix`'s channel (channels::prefixed(channel, prefix); "" none).
  template <class T>
  void writeAs(const std::string& prefix, channels::Channel<T> channel, const std::type_identity_t<T>& value,
               int64_t utime) {
    const auto msg = toWire(value);
    std::vector<uint8_t> buf(static_cast<size_t>(msg.getEncodedSize()));
    msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
    writeRaw(channels::prefixed(channel, prefix), buf, utime);
  }
  void writeRaw(const std::string& channel, const std::vector<uint8_t>& bytes, int64_t utime);
  const std::string& path() const { return path_; }
  int64_t written() const { return written_; }

  /// Calls `fn(channel, rbuf)` for every event of the journal at `path` in order (nothing when
  /// the file does not exist). Returns the number of events.
  static int64_t read(const std::string& path,
                      const std::function<void(const std::string& channel, const lcm::ReceiveBuffer& rbuf)>& fn);

  /// Decodes `rbuf`, an event of `channel`, as the channel's LCM type (or its previous version:
  /// transport/wire_versions.h) and converts it; false
  /// (counted "<CHANNEL>:journal_bad_event" in `diag`) when it does not decode or convert.
  template <class T>
  static bool decode(const lcm::ReceiveBuffer& rbuf, channels::Channel<T> channel, std::type_identity_t<T>& out,
                     Diagnostics& diag) {
    WireType<T> msg;
    try {
      if (decodeAnyVersion(rbuf.data, rbuf.data_size, msg) >= 0) {  // a journal of an older build too
        out = fromWire<T>(msg);
        return true;
      }
    } catch (const std::exception&) {
    }
    diag.count(std::string(channel.name) + ":journal_bad_event");
    return false;
  }

 private:
  std::string path_;
  std::unique_ptr<lcm::LogFile> log_;
  int64_t written_ = 0;
};

}  // namespace meshnav::transport
