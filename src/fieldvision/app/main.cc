// fieldvision: turn ordinary cameras around a sports field into a measuring instrument.
#include <exception>
#include <iostream>

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>

#include "fieldvision/app/command.h"
#include "fieldvision/util/error.h"

namespace {

std::string FirstLine(const std::string& s) {
  std::string line = s.substr(0, s.find('\n'));
  while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.pop_back();
  return line;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "fieldvision: calibrate cameras against a sports field, find the ball, place it in 3D, fit "
      "its flight, plan camera rigs and track players."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "fieldvision 0.1.0");
  app.add_flag_callback(
      "-v,--verbose", [] { spdlog::set_level(spdlog::level::debug); }, "Print debug messages");
  int exit_code = 0;
  fv::app::SetUpAllCommands(app, exit_code);
  spdlog::set_pattern("%^%l%$: %v");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const fv::Error& e) {
    std::cerr << "fieldvision: error: " << FirstLine(e.what()) << "\n";
    return 1;
  } catch (const cv::Exception& e) {
    std::cerr << "fieldvision: error: OpenCV: " << FirstLine(e.msg) << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "fieldvision: error: " << FirstLine(e.what()) << "\n";
    return 1;
  }
  return exit_code;
}
