// ZeroMQ addresses as the commands and the studio take them: tcp://HOST:PORT (HOST not empty,
// PORT 1..65535; where the address is bound, also * or 0 for a free port) or ipc://PATH.
#pragma once

#include <string>

namespace fv::net {

// "" when `text` is such an address, else a one-line reason naming it.
std::string EndpointProblem(const std::string& text, bool bind);

}  // namespace fv::net
