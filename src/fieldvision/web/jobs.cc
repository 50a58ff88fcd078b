#include "fieldvision/web/jobs.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/progress.h"

namespace fv::web {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

const std::set<std::string> kCommands = {"ball", "trajectory", "players", "stats",
                                         "plan", "detect",     "synth"};
// Options whose value is a file or folder the job reads (must exist) or writes.
const std::set<std::string> kInputs = {
    "--camera", "--video",      "--in",    "--tracks", "--rig",    "--detections", "--truth",
    "--zones",  "--timestamps", "--scene", "--teams",  "--mounts", "--onnx"};
const std::set<std::string> kOutputs = {
    "--out",         "--draw",    "--save-detections",  "--mot-out",
    "--flights-dir", "--flights", "--write-detections", "--images",
    "--report",      "--smoothed"};
// Options whose value is a name or, when it looks like one, a file.
const std::set<std::string> kNameOrFile = {"--color", "--field", "--model"};

bool LooksLikePath(const std::string& v) {
  return v.find('/') != std::string::npos || v.rfind('.', 0) == 0 ||
         (v.size() > 5 && v.substr(v.size() - 5) == ".json");
}

}  // namespace

std::vector<std::string> CheckJobArguments(const Workspace& ws, const std::string& command,
                                           const std::vector<std::string>& args, bool replace) {
  if (!kCommands.count(command)) {
    std::string names;
    for (const auto& c : kCommands) names += (names.empty() ? "" : ", ") + c;
    throw HttpError(400, "job command '" + command + "' is not one of " + names);
  }
  std::vector<std::string> argv = {command};
  std::string option;
  for (const auto& a : args) {
    if (a.rfind("--", 0) == 0) {
      if (a.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-", 2) != std::string::npos) {
        throw HttpError(400, "job option '" + a + "' is not an option name (use '--opt value')");
      }
      option = a;
      argv.push_back(a);
      continue;
    }
    const bool input = kInputs.count(option) || (kNameOrFile.count(option) && LooksLikePath(a));
    if (input || kOutputs.count(option)) {
      const fs::path resolved = ws.Resolve(a, input);
      std::error_code ec;
      const bool taken =
          fs::is_directory(resolved, ec) ? !fs::is_empty(resolved, ec) : fs::exists(resolved, ec);
      if (!input && taken && !replace) {
        throw HttpError(
            409, fmt::format("'{}' ({}) exists: choose another name, or replace it (replace: true)",
                             a, option));
      }
      argv.push_back(resolved.string());
    } else if (LooksLikePath(a) || a.find('/') != std::string::npos) {
      throw HttpError(400, "job argument '" + a + "' looks like a path, but " +
                               (option.empty() ? "no option" : "option " + option) +
                               " does not name files");
    } else {
      argv.push_back(a);
    }
    option.clear();
  }
  return argv;
}

struct JobRunner::Job {
  int id = 0;
  std::string command;
  std::vector<std::string> args;
  pid_t pid = -1;
  std::string state = "running";
  int exit_code = -1;
  bool cancel_requested = false;
  std::string progress;
  std::string output;  // the last 4000 characters
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  double elapsed_s = 0.0;
  std::thread watcher;
};

JobRunner::JobRunner(std::string program, const Workspace& workspace, EventHub* events)
    : program_(std::move(program)), workspace_(workspace), events_(events) {}

JobRunner::~JobRunner() {
  std::vector<Job*> all;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto& [id, job] : jobs_) {
      if (job->state == "running" && job->pid > 0) {
        job->cancel_requested = true;
        kill(-job->pid, SIGTERM);
      }
      all.push_back(job.get());
    }
  }
  // A job that has not ended 5 s after SIGTERM is killed.
  for (int i = 0; i < 100; ++i) {
    bool running = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (Job* j : all) running = running || j->state == "running";
    }
    if (!running) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (Job* j : all) {
      if (j->state == "running" && j->pid > 0) kill(-j->pid, SIGKILL);
    }
  }
  for (Job* j : all) {
    if (j->watcher.joinable()) j->watcher.join();
  }
}

int JobRunner::Start(const std::string& command, const std::vector<std::string>& args,
                     bool replace) {
  const std::vector<std::string> argv_strings = [&] {
    std::vector<std::string> a = CheckJobArguments(workspace_, command, args, replace);
    a.insert(a.begin(), program_);
    return a;
  }();
  std::vector<char*> argv;
  argv.reserve(argv_strings.size() + 1);
  for (const auto& s : argv_strings) argv.push_back(const_cast<char*>(s.c_str()));
  argv.push_back(nullptr);
  const std::string root = workspace_.root().string();

  // The server blocks SIGINT/SIGTERM in its threads (RunStudio) and a child inherits the mask:
  // the job gets an empty one, so that cancel's SIGTERM ends it.
  sigset_t no_signals;
  sigemptyset(&no_signals);
  int fds[2];
  FV_REQUIRE(pipe2(fds, O_CLOEXEC) == 0, "studio: cannot create a pipe for a job");
  // The environment with progress lines asked for (util/progress.h): the jobs page shows them.
  const std::string progress_env = fmt::format("{}={}", util::kProgressEnv, util::kProgressLines);
  std::vector<char*> envp;
  for (char** e = environ; *e != nullptr; ++e) {
    if (std::strncmp(*e, util::kProgressEnv, std::strlen(util::kProgressEnv)) != 0 ||
        (*e)[std::strlen(util::kProgressEnv)] != '=') {
      envp.push_back(*e);
    }
  }
  envp.push_back(const_cast<char*>(progress_env.c_str()));
  envp.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    Throw("studio: cannot start a job (fork failed)");
  }
  if (pid == 0) {  // the child: only async-signal-safe calls until exec
    setpgid(0, 0);
    sigprocmask(SIG_SETMASK, &no_signals, nullptr);
    dup2(fds[1], STDOUT_FILENO);
    dup2(fds[1], STDERR_FILENO);
    const int null_fd = open("/dev/null", O_RDONLY);
    if (null_fd >= 0) dup2(null_fd, STDIN_FILENO);
    if (chdir(root.c_str()) != 0) _exit(126);
    execve(argv[0], argv.data(), envp.data());
    // Said in the job's output (it showed "failed (exit 127)" and nothing else).
    static constexpr char kNotStarted[] =
        "studio: the job's program could not be started (moved, removed or being rebuilt?)\n";
    [[maybe_unused]] const ssize_t n = write(STDERR_FILENO, kNotStarted, sizeof(kNotStarted) - 1);
    _exit(127);
  }
  setpgid(pid, pid);
  close(fds[1]);
  std::lock_guard<std::mutex> lock(mutex_);
  auto job = std::make_unique<Job>();
  job->id = next_id_++;
  job->command = command;
  job->args = args;
  job->pid = pid;
  Job* raw = job.get();
  const int read_fd = fds[0];
  jobs_[raw->id] = std::move(job);
  raw->watcher = std::thread([this, raw, read_fd] { Watch(raw, read_fd); });
  if (events_) events_->Publish("job", ToJson(*raw));
  return raw->id;
}

void JobRunner::Watch(Job* job, int fd) {
  char buf[4096];
  auto last_event = std::chrono::steady_clock::now();
  std::string line;
  for (;;) {
    const ssize_t n = read(fd, buf, sizeof(buf));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    std::lock_guard<std::mutex> lock(mutex_);
    job->output.append(buf, n);
    if (job->output.size() > 4000) job->output.erase(0, job->output.size() - 4000);
    // The progress line: the last complete line (progress bars end theirs with '\r').
    for (ssize_t i = 0; i < n; ++i) {
      if (buf[i] == '\r' || buf[i] == '\n') {
        if (!line.empty()) job->progress = line;
        line.clear();
      } else {
        line += buf[i];
      }
    }
    const auto now = std::chrono::steady_clock::now();
    if (events_ && now - last_event > std::chrono::milliseconds(250)) {
      last_event = now;
      job->elapsed_s = std::chrono::duration<double>(now - job->start).count();
      events_->Publish("job", ToJson(*job));
    }
  }
  close(fd);
  int status = 0;
  while (waitpid(job->pid, &status, 0) < 0 && errno == EINTR) {
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (!line.empty()) job->progress = line;
  job->exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  job->state = job->cancel_requested ? "cancelled" : job->exit_code == 0 ? "done" : "failed";
  job->elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - job->start).count();
  if (events_) events_->Publish("job", ToJson(*job));
}

bool JobRunner::Cancel(int id) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = jobs_.find(id);
  if (it == jobs_.end()) throw HttpError(404, "no job " + std::to_string(id));
  Job& job = *it->second;
  if (job.state != "running") return false;
  job.cancel_requested = true;
  kill(-job.pid, SIGTERM);
  return true;
}

json JobRunner::ToJson(const Job& job) const {
  return {{"id", job.id},         {"command", job.command},     {"args", job.args},
          {"state", job.state},   {"exit_code", job.exit_code}, {"progress", job.progress},
          {"output", job.output}, {"elapsed_s", job.elapsed_s}};
}

json JobRunner::Get(int id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = jobs_.find(id);
  if (it == jobs_.end()) throw HttpError(404, "no job " + std::to_string(id));
  json j = ToJson(*it->second);
  if (it->second->state == "running") {
    j["elapsed_s"] =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - it->second->start).count();
  }
  return j;
}

json JobRunner::List() const {
  json all = json::array();
  std::vector<int> ids;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [id, job] : jobs_) ids.push_back(id);
  }
  for (auto it = ids.rbegin(); it != ids.rend(); ++it) all.push_back(Get(*it));
  return all;
}

}  // namespace fv::web
