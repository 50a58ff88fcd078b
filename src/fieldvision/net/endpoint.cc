#include "fieldvision/net/endpoint.h"

#include <fmt/format.h>

namespace fv::net {

std::string EndpointProblem(const std::string& text, bool bind) {
  std::string bad = fmt::format("'{}' is not tcp://HOST:PORT (PORT 1..65535{}) or ipc://PATH",
                                text.substr(0, 200), bind ? ", or * or 0 for a free one" : "");
  if (text.rfind("ipc://", 0) == 0) return text.size() > 6 ? std::string() : bad;
  if (text.rfind("tcp://", 0) != 0) return bad;
  const std::string rest = text.substr(6);
  const size_t colon = rest.rfind(':');
  if (colon == std::string::npos || colon == 0) return bad;
  const std::string port = rest.substr(colon + 1);
  if (bind && port == "*") return "";
  if (port.empty() || port.size() > 5 ||
      port.find_first_not_of("0123456789") != std::string::npos) {
    return bad;
  }
  const int p = std::stoi(port);
  return (p >= 1 || (bind && p == 0)) && p <= 65535 ? std::string() : bad;
}

}  // namespace fv::net
