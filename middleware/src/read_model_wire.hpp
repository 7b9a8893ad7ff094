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

/// A record, in a history answer and in an event-stream message alike.
wire::RecordEntry to_wire(const introspect::HistoryEntry& e);
bool from_wire(const wire::RecordEntry& w, introspect::HistoryEntry& out);

/// An explanation: its level travels as its root's.
wire::ExplainEntry to_wire(const Explanation& e);
Explanation from_wire(const wire::ExplainEntry& w);

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
