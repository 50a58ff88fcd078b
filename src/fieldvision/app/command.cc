#include "fieldvision/app/command.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

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

CLI::App* CommandGroup(CLI::App& app, const std::string& name, const std::string& description) {
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    if (sub->get_name() == name) return sub;
  }
  CLI::App* group = app.add_subcommand(name, description);
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

}  // namespace fv::app
