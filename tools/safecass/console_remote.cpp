// `safecass console --ice` / `safecass timeline --ice`: a live coordinator through RemoteClient.

#include "console_remote.hpp"

#include <chrono>
#include <cstdio>

#include "console_shell.hpp"
#include "safecass/introspect/format.hpp"
#include "safecass/middleware/client.hpp"
#include "safecass/middleware/token.hpp"
#include "safecass/timeline/timeline.hpp"

namespace safecass::tools {

using middleware::RemoteClient;

namespace {

[[nodiscard]] Expected<std::unique_ptr<RemoteClient>> connect_client(
    const std::string& ice, const std::string& coordinator, const std::string& token, int timeout_ms,
    const std::string& keys, bool insecure, const std::string& tls = {}, const std::string& read_token = {}) {
  auto endpoint = middleware::parse_ice_endpoint(ice);
  if (!endpoint) return fail(ErrorCode::Parse, endpoint.error().message);  // names --ice and its text
  middleware::ClientOptions o;
  o.ice = *endpoint;
  o.coordinator = coordinator;
  o.token = token;
  o.keys_dir = keys;
  o.insecure = insecure;
  o.tls.dir = tls;
  o.read_token = read_token;
  o.timeout = std::chrono::milliseconds(timeout_ms);
  auto client = RemoteClient::connect(o);
  if (!client) return tl::unexpected(client.error());
  return client;
}

}  // namespace

[[nodiscard]] Expected<std::unique_ptr<Console>> connect_console(const ConsoleArgs& args) {
  std::string token;
  if (!args.token_file.empty()) {
    auto t = middleware::read_token_file(args.token_file);
    if (!t) return fail(t.error().code, "console: --token-file: " + t.error().message);
    token = *t;
  }
  std::string read_token;
  if (!args.read_token_file.empty()) {
    auto t = middleware::read_token_file(args.read_token_file);
    if (!t) return fail(t.error().code, "console: --read-token-file: " + t.error().message);
    read_token = *t;
  }
  auto client = connect_client(args.ice, args.coordinator, token, args.timeout_ms, args.keys, args.insecure, args.tls,
                               read_token);
  if (!client) return fail(client.error().code, "console: " + client.error().message);
  const ConsoleOptions options{args.json, args.allow_write};
  Target target;
  target.subject = "coordinator " + args.coordinator + " on IceStorm " + args.ice;
  if (auto names = (*client)->names(); names) {
    target.subject += " (" + std::to_string(names->components.size()) + " components)";
  }
  target.write_access = args.token_file.empty()
                            ? "writes allowed, but no --token-file: the coordinator will refuse them"
                            : "writes allowed (token from " + args.token_file + ")";
  target.query = std::move(*client);
  auto backend = make_backend(std::move(target), options);
  if (!backend) return fail(backend.error().code, "console: " + backend.error().message);
  return std::make_unique<Console>(std::move(*backend), options);
}

int run_timeline_ice(const std::string& ice, const std::string& coordinator, const std::string& html_out,
                     int timeout_ms, const std::string& keys, const std::string& tls,
                     const std::string& read_token_file) {
  std::string read_token;
  if (!read_token_file.empty()) {
    auto t = middleware::read_token_file(read_token_file);
    if (!t) {
      std::fprintf(stderr, "safecass timeline: --read-token-file: %s\n", t.error().message.c_str());
      return 2;
    }
    read_token = *t;
  }
  auto client = connect_client(ice, coordinator, {}, timeout_ms, keys, false, tls, read_token);
  if (!client) {
    std::fprintf(stderr, "safecass timeline: %s\n", client.error().message.c_str());
    return 2;
  }
  auto records = (*client)->history("SYSTEM", 0);
  if (!records) {
    std::fprintf(stderr, "safecass timeline: %s\n", records.error().message.c_str());
    return 2;
  }
  const std::vector<timeline::HistoryRecord> drawn = timeline::records_of(*records);
  const int written =
      timeline::write_timeline_page(drawn, "coordinator " + coordinator + " (live, IceStorm " + ice + ")", html_out);
  if (written != 0) return written;
  std::fprintf(stderr, "safecass timeline: %zu records of coordinator '%s' drawn in %s\n", drawn.size(),
               coordinator.c_str(), html_out.c_str());
  return 0;
}

}  // namespace safecass::tools
