// fieldvision: turn ordinary cameras around a sports field into a measuring instrument.
#include <cstdlib>
#include <exception>
#include <iostream>

#include <glog/logging.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>

#include "fieldvision/app/command.h"
#include "fieldvision/codecs/codecs.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace {

std::string FirstLine(const std::string& s) {
  std::string line = s.substr(0, s.find('\n'));
  while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.pop_back();
  return line;
}

// Library log spam never reaches the user (one line per error): OpenCV, FFmpeg (read by OpenCV
// when its first capture opens), GStreamer and Ceres' glog are quiet unless --verbose.
void QuietLibraries(bool verbose) {
  cv::utils::logging::setLogLevel(verbose ? cv::utils::logging::LOG_LEVEL_INFO
                                          : cv::utils::logging::LOG_LEVEL_SILENT);
  // A user's own settings stand unless --verbose.
  setenv("OPENCV_FFMPEG_LOGLEVEL", verbose ? "32" : "-8", verbose);  // AV_LOG_INFO / AV_LOG_QUIET
  setenv("GST_DEBUG", verbose ? "2" : "0", verbose);
  FLAGS_minloglevel = verbose ? google::GLOG_INFO : google::GLOG_FATAL;
  fv::codecs::SetLibraryLogs(verbose);
}

// FFmpeg conceals damaged video data (a cut download, a bad card) and OpenCV hands on the frames
// without a word: results from them, and from the frames that refer to them, may be wrong.
void WarnOfDamagedVideo() {
  const long long problems = fv::codecs::DecoderProblems();
  if (problems <= 0) return;
  std::cerr << "fieldvision: warning: the video decoder reported damaged data " << problems
            << (problems == 1 ? " time" : " times")
            << " (frames concealed): results from those frames and the ones after them may be "
               "wrong\n";
}

// Help without CLI11's flag values: "--no-legend{false}" (the value a negated flag gives) reads
// as a syntax to type; the option's name alone is what a user types.
class HelpFormatter : public CLI::Formatter {
 public:
  std::string make_option_name(const CLI::Option* opt, bool is_positional) const override {
    const std::string name = CLI::Formatter::make_option_name(opt, is_positional);
    return fv::util::ReplaceAll(fv::util::ReplaceAll(name, "{false}", ""), "{true}", "");
  }
};

int Run(int argc, char** argv) {
  CLI::App app{
      "fieldvision: calibrate cameras against a sports field, find the ball, place it in 3D, fit "
      "its flight, plan camera rigs and track players."};
  app.formatter(std::make_shared<HelpFormatter>());
  app.require_subcommand(1);
  app.set_version_flag("--version", "fieldvision 0.1.0");
  QuietLibraries(false);
  app.add_flag_callback(
      "-v,--verbose",
      [] {
        spdlog::set_level(spdlog::level::debug);
        QuietLibraries(true);
      },
      "Print debug messages");
  int exit_code = 0;
  fv::app::SetUpAllCommands(app, exit_code);
  spdlog::set_pattern("%^%l%$: %v");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // `fieldvision bogus`: CLI11 says only "A subcommand is required".
    const std::string first = argc > 1 ? argv[1] : "";
    if (!first.empty() && first[0] != '-' &&
        app.get_subcommands([&](const CLI::App* s) { return s->check_name(first); }).empty()) {
      std::cerr << "fieldvision: error: unknown subcommand '" << first
                << "' (fieldvision --help lists them)\n";
      return e.get_exit_code();
    }
    std::cerr << "fieldvision: error: " << FirstLine(e.what()) << "\n";  // one line
    return e.get_exit_code();
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
  WarnOfDamagedVideo();
  return exit_code;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Run(argc, argv);
  } catch (const std::exception& e) {  // while setting up, before the commands' own handling
    std::cerr << "fieldvision: error: " << FirstLine(e.what()) << "\n";
  } catch (...) {
    std::cerr << "fieldvision: error: unknown exception\n";
  }
  return 1;
}
