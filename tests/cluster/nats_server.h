// SPDX-License-Identifier: AGPL-3.0-or-later
// A nats-server with JetStream on loopback for one test: its own store
// directory, a free port, stopped (or killed) by the test or at the end.
#pragma once

#include <signal.h>
#include <sys/prctl.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>

namespace labelmesh::testing {

class NatsServer {
 public:
  // Starts the server with its store in `dir`; port 0 picks a free one.
  explicit NatsServer(std::filesystem::path dir, int port = 0) : dir_(std::move(dir)) {
    start(port);
  }
  ~NatsServer() { stop(SIGKILL); }

  const std::string& url() const { return url_; }
  int port() const { return port_; }
  bool running() const { return pid_ > 0; }

  // SIGTERM (a clean stop) or SIGKILL, and wait for it.
  void stop(int signal = SIGTERM) {
    if (pid_ <= 0) return;
    kill(pid_, signal);
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
  }

  // Starts it again on the same port and store: what a restarted pod does.
  void restart() {
    stop();
    start(port_);
  }

 private:
  void start(int port) {
    const auto ports_dir = dir_ / "ports";
    std::filesystem::remove_all(ports_dir);
    std::filesystem::create_directories(ports_dir);
    const std::string store = (dir_ / "store").string();
    const std::string port_text = port > 0 ? std::to_string(port) : "-1";
    const std::string ports_text = ports_dir.string();
    const std::string log = (dir_ / "nats.log").string();
    pid_ = fork();
    if (pid_ == 0) {
      prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlive a test that crashed
      execlp("nats-server", "nats-server", "-js", "-a", "127.0.0.1", "-p", port_text.c_str(), "-sd",
             store.c_str(), "--ports_file_dir", ports_text.c_str(), "-l", log.c_str(),
             static_cast<char*>(nullptr));
      _exit(127);
    }
    // The ports file appears once the server listens.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    const std::regex client_url(R"re("nats":\s*\[\s*"(nats://127\.0\.0\.1:(\d+))")re");
    while (std::chrono::steady_clock::now() < deadline) {
      for (const auto& entry : std::filesystem::directory_iterator(ports_dir)) {
        std::ifstream in(entry.path());
        std::stringstream text;
        text << in.rdbuf();
        std::smatch match;
        const std::string content = text.str();
        if (std::regex_search(content, match, client_url)) {
          url_ = match[1];
          port_ = std::stoi(match[2]);
          return;
        }
      }
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  std::filesystem::path dir_;
  pid_t pid_ = -1;
  int port_ = 0;
  std::string url_;
};

}  // namespace labelmesh::testing
