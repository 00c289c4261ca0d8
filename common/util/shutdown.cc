#include "common/util/shutdown.h"

#include <csignal>

namespace mbslam {
namespace {

volatile std::sig_atomic_t g_shutdown = 0;
volatile std::sig_atomic_t g_signal = 0;

extern "C" void HandleShutdownSignal(int signum) {
  g_signal = signum;
  g_shutdown = 1;
}

}  // namespace

void InstallShutdownHandlers() {
  struct sigaction action = {};
  action.sa_handler = HandleShutdownSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: blocking calls return EINTR and loops re-check
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  std::signal(SIGPIPE, SIG_IGN);
}

bool ShutdownRequested() { return g_shutdown != 0; }

void RequestShutdown() { g_shutdown = 1; }

int ShutdownSignal() { return g_signal; }

}  // namespace mbslam
