// "host:port" of the --*-listen flags, split for the listeners that bind their own sockets (HTTP, health).
#pragma once

#include <string>

namespace k4reg::service {

struct ListenAddress {
  std::string host;  // without the brackets of an IPv6 literal
  int port = 0;      // 0 = ephemeral
};

// "0.0.0.0:8080", "[::]:8080". Throws std::runtime_error naming `flag` for anything else.
ListenAddress parse_listen_address(const std::string& listen, const std::string& flag);

}  // namespace k4reg::service
