// Compiled by the Ids.* tests (tests/unit/core/CMakeLists.txt), never linked: each SAFECASS_CASE_*
// selects one use of the ids. The correct use must compile; each mix-up must be refused by the
// compiler, because each kind of id is its own type (core/include/safecass/core/ids.hpp).

#include "safecass/core/coordinator.hpp"

namespace safecass {

State read(Coordinator& co) {
  const ComponentId component = *co.add_component("C");
  const MachineId machine = co.structure().application_machine(component);
  const EventId event = *co.structure().find_event("EVT_STALE");
  (void)machine;
  (void)event;
#if defined(SAFECASS_CASE_RIGHT_IDS)
  co.generate(event, machine);
  return co.state(machine);
#elif defined(SAFECASS_CASE_COMPONENT_AS_MACHINE)
  return co.state(component);  // a ComponentId where a MachineId is expected
#elif defined(SAFECASS_CASE_SWAPPED_EVENT_AND_MACHINE)
  co.generate(machine, event);  // the arguments in the wrong order
  return State::Normal;
#elif defined(SAFECASS_CASE_INTEGER_AS_MACHINE)
  return co.state(3u);  // a bare index where a MachineId is expected
#else
#error "define one SAFECASS_CASE_*"
#endif
}

}  // namespace safecass
