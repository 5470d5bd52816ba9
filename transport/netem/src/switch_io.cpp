#include "transport/netem/switch_io.h"

#include <sys/socket.h>
#include <sys/time.h>
#include <sys/uio.h>

#include <cstring>

namespace meshnav::netem {

void SwitchLag::add(int64_t late_us) {
  ++sent;
  if (late_us > kLateUs) ++late;
  if (late_us > max_us) max_us = late_us;
}

bool enableReceiveStamps(int fd) {
  const int one = 1;
  return setsockopt(fd, SOL_SOCKET, SO_TIMESTAMP, &one, sizeof one) == 0;
}

ssize_t receiveStamped(int fd, std::vector<uint8_t>& buf, int64_t fallback_us, int64_t& arrived_us) {
  iovec iov{buf.data(), buf.size()};
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timeval))];
  msghdr msg{};
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  msg.msg_control = control;
  msg.msg_controllen = sizeof control;
  const ssize_t got = recvmsg(fd, &msg, MSG_DONTWAIT);
  arrived_us = fallback_us;
  if (got < 0) return got;
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c))
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMP) {
      timeval tv{};
      std::memcpy(&tv, CMSG_DATA(c), sizeof tv);
      arrived_us = static_cast<int64_t>(tv.tv_sec) * 1'000'000 + tv.tv_usec;
    }
  return got;
}

}  // namespace meshnav::netem
