#include "transport/input_journal.h"

#include <filesystem>
#include <stdexcept>

namespace meshnav::transport {

InputJournal::InputJournal(std::string path) : path_(std::move(path)) {
  const auto dir = std::filesystem::path(path_).parent_path();
  if (!dir.empty()) std::filesystem::create_directories(dir);
  log_ = std::make_unique<lcm::LogFile>(path_, "a");
  if (!log_->good()) throw std::runtime_error(path_ + ": cannot open the input journal for appending");
}

InputJournal::~InputJournal() = default;

void InputJournal::writeRaw(const std::string& channel, const std::vector<uint8_t>& bytes, int64_t utime) {
  lcm::LogEvent ev{};
  ev.eventnum = written_;
  ev.timestamp = utime;
  ev.channel = channel;
  ev.datalen = static_cast<int32_t>(bytes.size());
  ev.data = const_cast<uint8_t*>(bytes.data());
  if (log_->writeEvent(&ev) != 0) throw std::runtime_error(path_ + ": cannot write the input journal");
  std::fflush(log_->getFilePtr());
  ++written_;
}

int64_t InputJournal::read(const std::string& path,
                           const std::function<void(const std::string&, const lcm::ReceiveBuffer&)>& fn) {
  if (!std::filesystem::exists(path)) return 0;
  lcm::LogFile log(path, "r");
  if (!log.good()) throw std::runtime_error(path + ": cannot read the input journal");
  int64_t n = 0;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    lcm::ReceiveBuffer rbuf{};
    rbuf.data = ev->data;
    rbuf.data_size = static_cast<uint32_t>(ev->datalen);
    rbuf.recv_utime = ev->timestamp;
    fn(ev->channel, rbuf);
    ++n;
  }
  return n;
}

}  // namespace meshnav::transport
