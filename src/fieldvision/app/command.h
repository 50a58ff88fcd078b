// Subcommand registration for the fieldvision program: each cmd_<name>.cc defines a function
// that adds its CLI11 subcommand and registers it with FV_REGISTER_COMMAND. The subcommand only
// parses options and calls a library function that tests call directly.
#pragma once

#include <functional>
#include <string>

#include <CLI/CLI.hpp>

namespace fv::app {

// Adds a subcommand to `app`; the callback it sets returns through `exit_code`.
using CommandSetup = std::function<void(CLI::App& app, int& exit_code)>;

struct CommandRegistration {
  // `order` sorts the subcommands in --help.
  CommandRegistration(int order, const std::string& name, CommandSetup setup);
};

void SetUpAllCommands(CLI::App& app, int& exit_code);

// A command group shared by several cmd_*.cc files ("calibrate", "eval", "color", "tracks"):
// returns the existing subcommand or adds it with the group's one description (command.cc).
CLI::App* CommandGroup(CLI::App& app, const std::string& name);

// An option check: a finite number in [lo, hi]. CLI::Range lets NaN through; CLI11 puts the
// option's name before the message ("--step: value nan is not a number in [0.001, 100]").
CLI::Validator FiniteRange(double lo, double hi);

// An option check for a network's input width: 0 (from the frame) or a multiple of 32 in
// 64..4096 (dnn/nanodet.h).
CLI::Validator NetworkWidth();

// An option check for a seed: digits only (CLI11 reads "-1" into an unsigned as 2^64 - 1).
CLI::Validator Seed();

// An option check for a ZeroMQ address: tcp://HOST:PORT (HOST not empty, PORT in 1..65535, or
// also * and 0 where `bind`) or ipc://PATH. ZeroMQ aborts the process on some malformed ones.
CLI::Validator Endpoint(bool bind);

}  // namespace fv::app

#define FV_CONCAT_INNER(a, b) a##b
#define FV_CONCAT(a, b) FV_CONCAT_INNER(a, b)
#define FV_REGISTER_COMMAND(order, name, setup) \
  static const ::fv::app::CommandRegistration FV_CONCAT(fv_command_, __LINE__)(order, name, setup)
