// Jobs of the studio: fieldvision subcommands (ball, trajectory, players, stats, plan, detect,
// synth) run as child processes of the server in the working folder, with their progress line
// and output streamed as "job" events (events.h) and a cancel that ends the process group.
// Every file an argument names must be inside the working folder (workspace.h).
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fieldvision/web/events.h"
#include "fieldvision/web/workspace.h"

namespace fv::web {

// The command line of a job after checking: the subcommand must be one of the allowed ones; the
// values of options that name files are resolved inside the folder (inputs must exist); any
// other value that looks like a path is refused; an output that exists (a file, a folder with
// files) is refused unless `replace` (the page's prefilled arguments would write over an earlier
// run's results). Throws HttpError 400/403/404/409.
std::vector<std::string> CheckJobArguments(const Workspace& workspace, const std::string& command,
                                           const std::vector<std::string>& args,
                                           bool replace = false);

class JobRunner {
 public:
  // `program`: the fieldvision executable the jobs run.
  JobRunner(std::string program, const Workspace& workspace, EventHub* events);
  // Cancels the jobs still running and waits for them.
  ~JobRunner();
  JobRunner(const JobRunner&) = delete;
  JobRunner& operator=(const JobRunner&) = delete;

  // Starts a job; returns its id. Throws HttpError for refused arguments, fv::Error when the
  // process cannot be started.
  int Start(const std::string& command, const std::vector<std::string>& args, bool replace = false);
  // Ends a running job (SIGTERM to its process group); false when it is not running.
  bool Cancel(int id);
  // {id, command, args, state (running|done|failed|cancelled), exit_code, progress, output,
  // elapsed_s}; List: every job, newest first. Get throws HttpError 404 for an unknown id.
  nlohmann::json Get(int id) const;
  nlohmann::json List() const;

 private:
  struct Job;
  void Watch(Job* job, int fd);
  nlohmann::json ToJson(const Job& job) const;

  std::string program_;
  Workspace workspace_;
  EventHub* events_;
  mutable std::mutex mutex_;
  std::map<int, std::unique_ptr<Job>> jobs_;
  int next_id_ = 1;
};

}  // namespace fv::web
