#include "fieldvision/net/line_channel.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <set>
#include <thread>

#include <gtest/gtest.h>

#include "fieldvision/util/error.h"

namespace fv {
namespace {

using std::chrono::milliseconds;

TEST(LineChannel, TwoNodesDeliverEveryLineInOrderPerNode) {
  LineServer server({});
  ASSERT_GT(server.port(), 0);
  auto node = [&](const std::string& name) {
    LineClient client("127.0.0.1", server.port());
    for (int i = 0; i < 200; ++i) client.Send(name + ":" + std::to_string(i));
  };
  std::thread a(node, "a"), b(node, "b");
  std::map<std::string, int> next;
  int received = 0;
  while (received < 400) {
    auto line = server.Next(milliseconds(5000));
    ASSERT_TRUE(line) << "timed out after " << received << " lines";
    const std::string who = line->line.substr(0, 1);
    EXPECT_EQ(std::stoi(line->line.substr(2)), next[who]++) << "out of order from " << who;
    ++received;
  }
  a.join();
  b.join();
  EXPECT_EQ(server.stats().lines, 400);
  EXPECT_EQ(server.stats().clients_connected, 2);
  EXPECT_FALSE(server.Next(milliseconds(50)));
}

TEST(LineChannel, OverLongAndPartialLinesAreDroppedNotBuffered) {
  LineServerOptions o;
  o.max_line_bytes = 64;
  LineServer server(o);
  {
    LineClient client("127.0.0.1", server.port());
    client.Send("ok1");
    client.Send(std::string(10000, 'x'));
    client.Send("ok2");
  }
  // A raw peer that dies in the middle of a line.
  {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<uint16_t>(server.port()));
    ::inet_pton(AF_INET, "127.0.0.1", &addr.sin_addr);
    ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)), 0);
    const std::string half = "{\"camera\": 0, \"fra";
    ASSERT_EQ(::send(fd, half.data(), half.size(), 0), static_cast<ssize_t>(half.size()));
    ::close(fd);
  }
  std::vector<std::string> lines;
  while (auto l = server.Next(milliseconds(300))) lines.push_back(l->line);
  EXPECT_EQ(lines, (std::vector<std::string>{"ok1", "ok2"}));
  EXPECT_EQ(server.stats().lines_too_long, 1);
  EXPECT_EQ(server.stats().partial_lines_lost, 1);
  EXPECT_EQ(server.stats().clients_open, 0);
}

TEST(LineChannel, ClearErrors) {
  EXPECT_THROW(ParseHostPort("localhost"), Error);
  EXPECT_THROW(ParseHostPort("localhost:99999"), Error);
  EXPECT_EQ(ParseHostPort("10.0.0.2:7000").second, 7000);
  // Nothing listens on this port (it was just released).
  int port = 0;
  { port = LineServer({}).port(); }
  try {
    LineClient c("127.0.0.1", port, milliseconds(100));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(std::to_string(port)), std::string::npos);
  }
  LineServerOptions bad;
  bad.bind_address = "not-an-ip";
  EXPECT_THROW(LineServer{bad}, Error);
  EXPECT_THROW(
      {
        LineServer s({});
        LineClient c("127.0.0.1", s.port());
        c.Send("two\nlines");
      },
      Error);
}

}  // namespace
}  // namespace fv
