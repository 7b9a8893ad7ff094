#pragma once
// Internal: the read model (introspect/model.hpp) to and from its Slice messages, field by field,
// so that a remote answer carries everything the in-process one has. Shared by the Control
// servant, the client and the node's event publisher.

#include "ice_util.hpp"
#include "safecass/introspect/model.hpp"

namespace safecass::middleware {

/// A root cause on the wire: one shape for a record's root, an explanation's and each root of a
/// state update (which also carry the root's level and hop path).
wire::Root root_to_wire(const ResolvedRoot& r, wire::Level level = wire::Level::Normal,
                        std::vector<std::string> path = {});
/// Field by field into `r`'s own storage: a root reused for every message does not allocate.
void root_from_wire(const wire::Root& w, ResolvedRoot& r);

wire::StateEntry to_wire(const introspect::StateRow& r);
/// Errors (false): an unknown kind or level (a malformed message).
bool from_wire(const wire::StateEntry& w, introspect::StateRow& out);

wire::RecordEntry to_wire(const introspect::HistoryEntry& e);
/// Fills the record fields of an event-stream message (its coordinator, incarnation and stream
/// sequence number are the publisher's).
void fill_message(const introspect::HistoryEntry& e, wire::EventMessage& m);
bool from_wire(const wire::RecordEntry& w, introspect::HistoryEntry& out);
bool from_wire(const wire::EventMessage& w, introspect::HistoryEntry& out);

wire::FilterEntry to_wire(const introspect::FilterRow& r);
introspect::FilterRow from_wire(const wire::FilterEntry& w);
wire::FilterDetails to_wire(const introspect::FilterInfo& i);
introspect::FilterInfo from_wire(const wire::FilterDetails& w);
wire::EventEntry to_wire(const introspect::EventRow& r);
introspect::EventRow from_wire(const wire::EventEntry& w);
wire::ConnectionEntry to_wire(const introspect::ConnectionRow& r);
introspect::ConnectionRow from_wire(const wire::ConnectionEntry& w);
wire::ServiceEntry to_wire(const introspect::ServiceRow& r);
introspect::ServiceRow from_wire(const wire::ServiceEntry& w);
wire::ExplainReply to_wire(const introspect::ExplainAnswer& a);
introspect::ExplainAnswer from_wire(const wire::ExplainReply& w);
wire::ClockEntry to_wire(const introspect::ClockInfo& c);
introspect::ClockInfo from_wire(const wire::ClockEntry& w);
wire::NamesEntry to_wire(const introspect::Names& n);
introspect::Names from_wire(const wire::NamesEntry& w);

}  // namespace safecass::middleware
