#pragma once
/// @file live_diff.hpp
/// The network-free part of the viewer's live source (MiddlewareSource): a coordinator's state
/// list as rows, the picture built from them, and the records that describe what changed
/// between two polls. Kept apart so that it can be tested without a running system.
///
/// A row is one line of a coordinator's `state list` (the middleware's Control::stateList):
/// for each local component in declaration order its "component" row, then s_F, s_A, each
/// s_P, each s_R and each s_S row. skeleton_rows() builds the same rows from a locally built
/// coordinator, so that the page shows the shape of a coordinator that has not answered yet.

#include <string>
#include <string_view>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/core/state.hpp"
#include "safecass/viewer/source.hpp"

namespace safecass::viewer {

/// One row of a coordinator's state list.
struct LiveRow {
  std::string address;      ///< "JR3", "JR3.s_A", "CONTROL.s_R.ForceData", "JR3.s_S.ForceData"
  std::string kind;         ///< component, s_F, s_A, s_P, s_R, s_S
  State state = State::Normal;
  std::string outstanding;  ///< the outstanding event; empty when Normal

  friend bool operator==(const LiveRow&, const LiveRow&) = default;
};

/// The rows `co` would answer to `state list` (every state Normal right after it was built):
/// its local components, in the order and with the kinds of the middleware's state list.
std::vector<LiveRow> skeleton_rows(const Coordinator& co);

/// The picture of one coordinator from its rows: a component per "component" row, holding the
/// machine rows that follow it whose address starts with its name. Rows of an unknown kind are
/// left out. The coordinator's state is the worst of its components'.
CoordinatorView coordinator_view(std::string name, const std::vector<LiveRow>& rows);

/// The records (record_to_json's format, without "seq") for every change from `before` to
/// `after` at time `t` (seconds): a "component-transition" per component row whose state
/// changed, and a "transition" per machine or service row (s_F, s_A, s_P, s_R, s_S) whose state
/// changed, each with the outstanding event of the new state (or of the old one when back to
/// Normal) as "event". A row present in only one of the two lists
/// counts as Normal in the other. Rows whose outstanding event alone changed give a transition
/// record too (same from and to), so that the page learns the new event. Order: `after`'s order.
std::vector<std::string> diff_records(const std::vector<LiveRow>& before, const std::vector<LiveRow>& after, double t);

/// A record saying that a coordinator became reachable, was lost or cannot be reached:
/// {"t":T,"kind":"coordinator","coordinator":NAME,"text":TEXT}.
std::string coordinator_record(std::string_view coordinator, std::string_view text, double t);

}  // namespace safecass::viewer
