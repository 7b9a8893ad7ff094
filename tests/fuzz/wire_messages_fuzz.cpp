// libFuzzer target for every bus message other than an event batch (wire_events), after its
// authentication (docs/security.md): a member holds a valid key, and a coordinator a valid
// certificate, so their malformed payloads reach the decoders. The first byte picks the message;
// the rest is its body, sealed or signed each time by member "robot" of robodoc's keyring
// (fuzz_bus.hpp) and opened by the supervisor as the receivers open it:
//   0 a state batch (sealed), each update's roots read (root_from_wire);
//   1 a heartbeat (signed, open_heartbeat); 2 a proof of life (signed); 3 a resync request (sealed);
//   4..13 a Control answer as a tool reads it from a coordinator (read_model_wire.hpp): state rows,
//   records, filter rows, a filter's details, event rows, connections, services, explain, clock,
//   names.
// Beyond "no crash, no sanitizer report": a member's seal or signature always holds, so a refusal
// is the body's; a record that reads writes the same record again after a round trip to the wire.
//
// SAFECASS_FUZZ_WRITE_SEEDS=DIR writes the seed corpus (one valid message of each kind) into DIR.

#include <Ice/Ice.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "auth.hpp"
#include "fuzz_bus.hpp"
#include "read_model_wire.hpp"
#include "receiver.hpp"
#include "safecass/introspect/format.hpp"

namespace {

using namespace safecass;

enum Kind : std::uint8_t {
  kState,
  kHeartbeat,
  kProof,
  kResync,
  kStateRows,
  kRecords,
  kFilterRows,
  kFilterDetails,
  kEventRows,
  kConnections,
  kServices,
  kExplain,
  kClock,
  kNames,
  kKinds
};

/// A sealed message of `kind` from robot opened by the supervisor; traps when the seal fails.
template <class T>
bool open_sealed_body(std::string_view kind, const Ice::ByteSeq& body, T& out) {
  fuzz::BusMembers& m = fuzz::bus_members();
  const std::string why = middleware::open_sealed(*m.supervisor, m.ice, m.robot->seal(kind, body), kind, out);
  if (why.empty()) return true;
  if (why != "sealed body is malformed") __builtin_trap();  // a member's seal holds
  return false;
}

/// A signed message of `kind` from robot, checked with the keyring; traps when the signature fails.
template <class T>
bool open_signed_body(std::string_view kind, const Ice::ByteSeq& body, T& out) {
  fuzz::BusMembers& m = fuzz::bus_members();
  const std::string why = middleware::open_signed(*m.keyring, m.ice, m.robot->sign(kind, body), kind, out);
  if (why.empty()) return true;
  if (why != "signed body is malformed") __builtin_trap();
  return false;
}

/// A Control answer of type T, each entry read as a tool reads it.
template <class T, class Read>
void answer(const Ice::ByteSeq& body, Read read) {
  T value;
  if (middleware::decode(fuzz::bus_members().ice, body, value)) read(value);
}

void state_batch(const Ice::ByteSeq& body) {
  wire::StateBatch batch;
  if (!open_sealed_body(middleware::kKindState, body, batch)) return;
  for (const wire::StateUpdate& u : batch.updates) {
    for (const wire::Root& root : u.roots) {
      ResolvedRoot r;
      middleware::root_from_wire(root, r);
    }
  }
}

void heartbeat(const Ice::ByteSeq& body) {
  fuzz::BusMembers& m = fuzz::bus_members();
  const middleware::OpenedHeartbeat h =
      middleware::open_heartbeat(*m.keyring, m.ice, m.robot->sign(middleware::kKindHeartbeat, body));
  // A member's signature holds (the body may name anything, a reason's words included).
  if (h.why.starts_with("a heartbeat signed 'robot': bad signature")) __builtin_trap();
}

void records(const wire::RecordEntrySeq& entries) {
  for (const wire::RecordEntry& w : entries) {
    introspect::HistoryEntry entry;
    if (!middleware::from_wire(w, entry)) continue;  // a malformed record: refused
    introspect::HistoryEntry again;
    if (!middleware::from_wire(middleware::to_wire(entry), again)) __builtin_trap();
    if (introspect::history_json(again) != introspect::history_json(entry)) __builtin_trap();
  }
}

template <class Seq>
void rows(const Seq& entries) {
  for (const auto& w : entries) (void)middleware::from_wire(w);
}

void write(const std::string& dir, Kind kind, const Ice::ByteSeq& body) {
  std::ofstream out(dir + "/kind" + std::to_string(kind), std::ios::binary);
  out.put(static_cast<char>(kind));
  out.write(reinterpret_cast<const char*>(body.data()), static_cast<std::streamsize>(body.size()));
}

void write_seeds(const std::string& dir) {
  const auto& ic = fuzz::bus_members().ice;
  wire::StateUpdate u{};
  u.stream = 1;
  u.seq = 1;
  u.state = wire::Level::Error;
  u.roots.push_back(wire::Root{"EVT_FORCE_ERROR",
                               "JR3.s_A",
                               1000,
                               wire::Level::Error,
                               "",
                               "",
                               0.0,
                               0,
                               false,
                               {"JR3.s_A", "CONTROL.s_R.ForceData"}});
  write(dir, kState, middleware::encode(ic, wire::StateBatch{"robot", 7, 0x5afeca55, {u}}));
  wire::Heartbeat h;
  h.coordinator = "robot";
  h.incarnation = 7;
  h.seq = 3;
  h.states = {4, 1};
  h.statesId = 12345;
  h.events = 2;
  h.components = {"JR3", "CONTROL"};
  h.control = "ssl -h 127.0.0.1 -p 4100";
  write(dir, kHeartbeat, middleware::encode(ic, h));
  write(dir, kProof, middleware::encode(ic, wire::Proof{{1, 2, 3, 4}, h}));
  write(dir, kResync, middleware::encode(ic, wire::ResyncRequest{"supervisor", 7, 1, "robot"}));
  write(dir, kStateRows,
        middleware::encode(ic, wire::StateEntrySeq{{"JR3.s_A", "application", wire::Level::Error, "EVT_FORCE_ERROR"}}));
  introspect::HistoryEntry e;
  e.seq = 1;
  e.kind = RecordKind::Transition;
  e.machine = "JR3.s_A";
  e.component = "JR3";
  e.from = State::Normal;
  e.to = e.level = State::Error;
  e.event = "EVT_FORCE_ERROR";
  write(dir, kRecords, middleware::encode(ic, wire::RecordEntrySeq{middleware::to_wire(e)}));
  for (Kind k : {kFilterRows, kFilterDetails, kEventRows, kConnections, kServices, kExplain, kClock, kNames})
    write(dir, k, {});
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
  if (size == 0) return 0;
  const Ice::ByteSeq body(data + 1, data + size);
  switch (static_cast<Kind>(data[0] % kKinds)) {
    case kState: state_batch(body); break;
    case kHeartbeat: heartbeat(body); break;
    case kProof: {
      wire::Proof proof;
      (void)open_signed_body(middleware::kKindProof, body, proof);
      break;
    }
    case kResync: {
      wire::ResyncRequest request;
      (void)open_sealed_body(middleware::kKindResync, body, request);
      break;
    }
    case kStateRows:
      answer<wire::StateEntrySeq>(body, [](const wire::StateEntrySeq& entries) {
        for (const wire::StateEntry& w : entries) {
          introspect::StateRow row;
          (void)middleware::from_wire(w, row);
        }
      });
      break;
    case kRecords: answer<wire::RecordEntrySeq>(body, records); break;
    case kFilterRows: answer<wire::FilterEntrySeq>(body, rows<wire::FilterEntrySeq>); break;
    case kFilterDetails:
      answer<wire::FilterDetails>(body, [](const wire::FilterDetails& w) { (void)middleware::from_wire(w); });
      break;
    case kEventRows: answer<wire::EventEntrySeq>(body, rows<wire::EventEntrySeq>); break;
    case kConnections: answer<wire::ConnectionEntrySeq>(body, rows<wire::ConnectionEntrySeq>); break;
    case kServices: answer<wire::ServiceEntrySeq>(body, rows<wire::ServiceEntrySeq>); break;
    case kExplain:
      answer<wire::ExplainReply>(body, [](const wire::ExplainReply& w) { (void)middleware::from_wire(w); });
      break;
    case kClock:
      answer<wire::ClockEntry>(body, [](const wire::ClockEntry& w) { (void)middleware::from_wire(w); });
      break;
    case kNames:
      answer<wire::NamesEntry>(body, [](const wire::NamesEntry& w) { (void)middleware::from_wire(w); });
      break;
    case kKinds: break;
  }
  return 0;
}
