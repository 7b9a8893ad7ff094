#pragma once
/// @file live_diff.hpp
/// The viewer's picture of a coordinator, made from the read model's state list
/// (introspect::StateRow, in the one order introspect::LocalQuery computes: each component's
/// extended state, then s_F, s_A, each s_P, each s_R and each s_S). Both sources use it: the
/// in-process one with a LocalQuery, the live one with each coordinator's RemoteClient. Kept apart
/// so that it can be tested without a running system.

#include <string>
#include <string_view>
#include <vector>

#include "safecass/introspect/model.hpp"
#include "safecass/viewer/source.hpp"

namespace safecass::viewer {

/// The picture of one coordinator from its rows: a component per component row, holding the
/// machine and service rows that follow it whose address starts with its name. A SYSTEM row is
/// left out. The coordinator's state is the worst of its components'.
CoordinatorView coordinator_view(std::string name, const std::vector<introspect::StateRow>& rows);

/// A record saying that a coordinator became reachable, was lost or cannot be reached:
/// {"t":T,"kind":"coordinator","coordinator":NAME,"text":TEXT}.
std::string coordinator_record(std::string_view coordinator, std::string_view text, double t);

}  // namespace safecass::viewer
