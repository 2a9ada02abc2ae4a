#include "http/listen_address.h"

#include <stdexcept>

namespace k4reg::service {

ListenAddress parse_listen_address(const std::string& listen, const std::string& flag) {
  const auto colon = listen.rfind(':');
  std::string host = listen.substr(0, colon == std::string::npos ? 0 : colon);
  const std::string port = colon == std::string::npos ? "" : listen.substr(colon + 1);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  if (host.empty() || port.empty() || port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos ||
      std::stoi(port) > 65535)
    throw std::runtime_error(flag + " " + listen + ": expected host:port");
  return {host, std::stoi(port)};
}

}  // namespace k4reg::service
