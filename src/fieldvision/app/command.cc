#include "fieldvision/app/command.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include <fmt/format.h>

#include "fieldvision/net/endpoint.h"
#include "fieldvision/util/error.h"

namespace fv::app {
namespace {

struct Entry {
  int order;
  std::string name;
  CommandSetup setup;
};

std::vector<Entry>& Registry() {
  static std::vector<Entry> entries;
  return entries;
}

}  // namespace

CommandRegistration::CommandRegistration(int order, const std::string& name, CommandSetup setup) {
  Registry().push_back({order, name, std::move(setup)});
}

void SetUpAllCommands(CLI::App& app, int& exit_code) {
  auto entries = Registry();
  std::sort(entries.begin(), entries.end(),
            [](const Entry& a, const Entry& b) { return a.order < b.order; });
  for (const auto& e : entries) e.setup(app, exit_code);
}

CLI::App* CommandGroup(CLI::App& app, const std::string& name) {
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    if (sub->get_name() == name) return sub;
  }
  static const std::map<std::string, std::string> kDescriptions = {
      {"calibrate",
       "Calibrate cameras: intrinsics, pose from field points, refinement against lines"},
      {"color", "Colour classes for the ball"},
      {"eval", "Compare results with ground truth"},
      {"tracks", "Fix player tracks by hand"}};
  const auto description = kDescriptions.find(name);
  FV_REQUIRE(description != kDescriptions.end(), "no command group '{}'", name);
  CLI::App* group = app.add_subcommand(name, description->second);
  group->require_subcommand(1);
  return group;
}

CLI::Validator FiniteRange(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) {
        double v = 0;
        if (!CLI::detail::lexical_cast(text, v) || !std::isfinite(v) || v < lo || v > hi) {
          return fmt::format("value {} is not a number in [{}, {}]", text, lo, hi);
        }
        return std::string();
      },
      fmt::format("NUMBER in [{}, {}]", lo, hi));
}

CLI::Validator NetworkWidth() {
  return CLI::Validator(
      [](std::string& text) {
        int w = -1;
        const bool ok =
            CLI::detail::lexical_cast(text, w) && (w == 0 || (w >= 64 && w <= 4096 && w % 32 == 0));
        return ok ? std::string()
                  : fmt::format("'{}': give 0 (the frame's width) or a multiple of 32 in 64..4096",
                                text);
      },
      "0 or 64..4096 by 32");
}

CLI::Validator Seed() {
  return CLI::Validator(
      [](std::string& text) {
        const bool digits = !text.empty() && text.size() <= 19 &&
                            text.find_first_not_of("0123456789") == std::string::npos;
        return digits ? std::string()
                      : fmt::format("'{}' is not a seed (a whole number from 0)", text);
      },
      "0..10^19");
}

CLI::Validator Endpoint(bool bind) {
  return CLI::Validator([bind](std::string& text) { return net::EndpointProblem(text, bind); },
                        "tcp://HOST:PORT");
}

}  // namespace fv::app
