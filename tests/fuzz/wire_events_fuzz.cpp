// libFuzzer target for a bus message after its authentication (docs/security.md): a member holds a
// valid key, so its malformed payloads reach the decoders. Any bytes are the body of an event
// batch that member "robot" seals for the keyring of robodoc (keys made by `safecass keys`' code
// at start); the supervisor opens it (open_sealed: the seal must hold, it was made by a member)
// and decodes it as the event stream's messages, each record read into the read model
// (read_model_wire.hpp, as the supervisor and every follower read records). Beyond "no crash, no
// sanitizer report": a genuine seal always opens; a body that does not decode is refused with
// its reason; a record that reads writes the same history line after a round trip to the wire.
//
// SAFECASS_FUZZ_WRITE_SEEDS=DIR writes the seed corpus (valid batches) into DIR and exits.

#include <Ice/Ice.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "auth.hpp"
#include "fuzz_bus.hpp"
#include "read_model_wire.hpp"
#include "safecass/introspect/format.hpp"

namespace {

using namespace safecass;

/// A record of robodoc as a coordinator publishes one: a transition with its root.
wire::EventMessage record(long long seq, const std::string& machine, wire::Level to) {
  introspect::HistoryEntry e;
  e.seq = static_cast<std::uint64_t>(seq);
  e.time = seconds_to_time(0.001 * static_cast<double>(seq));
  e.kind = RecordKind::Transition;
  e.machine = machine;
  e.component = machine.substr(0, machine.find('.'));
  e.from = State::Normal;
  e.to = to == wire::Level::Error ? State::Error : State::Warning;
  e.level = e.to;
  e.event = "EVT_FORCE_ERROR";
  e.severity = 50;
  wire::EventMessage m;
  m.coordinator = "robot";
  m.incarnation = 7;
  m.seq = seq;
  m.record = middleware::to_wire(e);
  return m;
}

void write_seeds(const std::string& dir) {
  fuzz::BusMembers& m = fuzz::bus_members();
  const std::vector<wire::EventMessageSeq> seeds{
      {record(1, "JR3.s_A", wire::Level::Error)},
      {record(2, "JR3.s_A", wire::Level::Error), record(3, "CONTROL.s_R.ForceData", wire::Level::Error)},
      {},
  };
  for (std::size_t k = 0; k < seeds.size(); ++k) {
    const Ice::ByteSeq body = middleware::encode(m.ice, seeds[k]);
    std::ofstream(dir + "/batch" + std::to_string(k + 1), std::ios::binary)
        .write(reinterpret_cast<const char*>(body.data()), static_cast<std::streamsize>(body.size()));
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  if (const char* dir = std::getenv("SAFECASS_FUZZ_WRITE_SEEDS"); dir != nullptr && *dir != '\0') {
    write_seeds(dir);
    std::exit(0);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::BusMembers& m = fuzz::bus_members();
  const wire::Signed sealed = m.robot->seal(middleware::kKindEvents, Ice::ByteSeq(data, data + size));
  wire::EventMessageSeq batch;
  const std::string why = middleware::open_sealed(*m.supervisor, m.ice, sealed, middleware::kKindEvents, batch);
  if (why == "bad seal (forged, corrupted, or from outside the keyring)") __builtin_trap();  // a member's seal holds
  if (!why.empty()) {
    if (why != "sealed body is malformed") __builtin_trap();
    return 0;
  }
  for (const wire::EventMessage& message : batch) {
    introspect::HistoryEntry entry;
    if (!middleware::from_wire(message.record, entry)) continue;  // a malformed record: refused
    introspect::HistoryEntry again;
    if (!middleware::from_wire(middleware::to_wire(entry), again)) __builtin_trap();
    if (introspect::history_json(again) != introspect::history_json(entry)) __builtin_trap();
  }
  return 0;
}
