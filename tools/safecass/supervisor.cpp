// `safecass supervisor SYSTEM --ice HOST:PORT [--lost-after MS] [--duration SECONDS]`: the
// system-wide view of a multi-process system (DESIGN §4). Prints every transition as it arrives
// (with --states-only: every service state),
// marks a coordinator whose heartbeat stops as lost (EVT_COORDINATOR_LOST on its components and,
// by propagation, on everything connected to them) and its recovery, and prints the view at exit.

#include <CLI/CLI.hpp>

#include <unistd.h>
#include <cstdio>
#include <mutex>

#include "middleware_commands.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/middleware/keys.hpp"
#include "safecass/middleware/supervisor.hpp"
#include "safecass/spec/load.hpp"
#include "stop_signals.hpp"

namespace safecass::tools {

namespace {

struct SupervisorArgs {
  std::string system;
  std::string ice;
  int lost_after_ms = 600;
  double duration = 0.0;
  std::string keys;
  bool insecure = false;
  bool states_only = false;
  std::string tls;
  std::string listen;
};

int run_supervisor(const SupervisorArgs& args) {
  const StopSignals stop_signals;  // before any thread starts
  const FilterRegistry& registry = builtin_filters();
  spec::LoadResult load = spec::load_system(args.system, registry);
  for (const auto& d : load.diagnostics) std::fprintf(stderr, "%s\n", spec::format(d).c_str());
  if (!load.ok()) return 2;
  auto endpoint = middleware::parse_ice_endpoint(args.ice);
  if (!endpoint) {
    std::fprintf(stderr, "safecass supervisor: %s\n", endpoint.error().message.c_str());
    return 2;
  }
  if (args.lost_after_ms <= 0) {
    std::fprintf(stderr, "safecass supervisor: --lost-after must be positive\n");
    return 2;
  }
  static std::mutex print_mutex;
  middleware::SupervisorOptions options;
  options.ice = *endpoint;
  options.lost_after = std::chrono::milliseconds(args.lost_after_ms);
  options.keys_dir = args.keys;
  options.registry = &registry;
  options.insecure = args.insecure;
  options.records = !args.states_only;
  options.tls.dir = args.tls;
  if (!args.listen.empty()) options.listen_host = args.listen;
  options.print = [](const std::string& line) {
    std::lock_guard lock(print_mutex);
    std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  };
  auto supervisor = middleware::Supervisor::create(*load.system, options);
  if (!supervisor) {
    std::fprintf(stderr, "safecass supervisor: %s\n", supervisor.error().message.c_str());
    return 2;
  }
  if (auto r = (*supervisor)->start(); !r) {
    std::fprintf(stderr, "safecass supervisor: %s\n", r.error().message.c_str());
    return 2;
  }
  options.print("safecass supervisor: system '" + load.system->name + "', IceStorm " + args.ice + ", pid " +
                std::to_string(::getpid()));
  (void)stop_signals.wait(deadline_after(args.duration));
  (*supervisor)->stop();
  options.print("safecass supervisor: system-wide view");
  for (const middleware::ViewRow& row : (*supervisor)->view()) {
    options.print("  " +
                  middleware::SupervisorLine::of_state(row.coordinator, row.address, row.state, row.cause).text());
  }
  for (const std::string& lost : (*supervisor)->lost()) options.print("  coordinator '" + lost + "' lost");
  return 0;
}

}  // namespace

void add_supervisor_command(CLI::App& app, int& code) {
  static SupervisorArgs args;
  auto* cmd = app.add_subcommand(
      "supervisor", "Watch a multi-process system through IceStorm: transitions, lost coordinators, system view");
  cmd->add_option("SYSTEM", args.system, "the system file its coordinators run")->required();
  cmd->add_option("--ice", args.ice,
                  "IceStorm at HOST:PORT (locator:HOST:PORT: a replicated IceStorm's IceGrid registry)")
      ->required();
  cmd->add_option("--lost-after", args.lost_after_ms,
                  "milliseconds without a heartbeat before a coordinator is lost (default 600)");
  cmd->add_option("--duration", args.duration, "stop after SECONDS (default: until SIGINT/SIGTERM)");
  cmd->add_option("--keys", args.keys,
                  "the system's bus keys (safecass keys SYSTEM --out DIR; default $SAFECASS_KEYS)");
  cmd->add_flag("--insecure", args.insecure,
                "accept a non-loopback IceStorm or listening address without TLS (unencrypted)");
  cmd->add_flag("--states-only", args.states_only,
                "watch the service states only: no event records, so no per-machine transitions and no "
                "system-wide history, at a fraction of the cost");
  cmd->add_option("--tls", args.tls,
                  "the certificates' directory (ca.pem, supervisor.pem/.key) when not the key directory, which is "
                  "used when it holds ca.pem");
  cmd->add_option("--listen", args.listen, "the address to serve on (default 127.0.0.1)");
  cmd->callback([&code] { code = run_supervisor(args); });
}

void add_keys_command(CLI::App& app, int& code) {
  static std::string system;
  static std::string out;
  static middleware::KeyOptions options;
  auto* cmd = app.add_subcommand("keys",
                                 "Create the keys of a multi-process system: a signing key pair per coordinator and "
                                 "for the supervisor, and the TLS certificates of the system's CA that admit them, "
                                 "IceStorm and the tools to the broker");
  cmd->add_option("SYSTEM", system, "the system file")->required();
  cmd->add_option("--out", out, "the key directory (created with mode 0700)")->required();
  cmd->add_flag("--replace", options.replace,
                "replace existing keys and certificates (every process must then restart with the new ones); "
                "the CA in the directory is kept");
  cmd->add_option("--address", options.addresses,
                  "another address the processes are reached at, for the certificates (IP:10.0.0.5 or "
                  "DNS:robot.local; repeatable)");
  cmd->add_option("--ca", options.ca_dir,
                  "sign with the CA of this key directory (its ca.pem and ca.key): systems that share one "
                  "IceStorm share its CA (only ca.pem is copied)");
  cmd->callback([&code] {
    const FilterRegistry& registry = builtin_filters();
    spec::LoadResult load = spec::load_system(system, registry);
    for (const auto& d : load.diagnostics) std::fprintf(stderr, "%s\n", spec::format(d).c_str());
    if (!load.ok()) {
      code = 2;
      return;
    }
    auto names = middleware::create_bus_keys(*load.system, out, options);
    if (!names) {
      std::fprintf(stderr, "safecass keys: %s\n", names.error().message.c_str());
      code = 2;
      return;
    }
    for (const std::string& n : *names) std::printf("%s/%s.secret\n", out.c_str(), n.c_str());
    std::printf("%s/keyring\n", out.c_str());
    std::printf("%s/ca.pem\n", out.c_str());
    for (const std::string& n : *names) std::printf("%s/%s.pem\n", out.c_str(), n.c_str());
    std::printf("%s/%s.pem\n%s/%s.pem\n", out.c_str(), std::string(middleware::kBrokerCertificate).c_str(), out.c_str(),
                std::string(middleware::kReaderCertificate).c_str());
    code = 0;
  });
}

}  // namespace safecass::tools
