#pragma once
// The JSON Schema of scenario files, for editors' completion and checking (`omniloc schema`), and
// the parameter reference docs/localizers.md generated from it. The parameter objects (localizers,
// vision, sensor noise) come from the parameter structs' field lists (core/params.hpp), so their
// keys, defaults, ranges and meanings are written once; the scenario's own top-level keys follow
// harness/scenario.cpp. The strict reader stays the authority: the schema lets an editor complete
// and flag keys, `omniloc validate` checks everything (cross-field rules, files, geometry).
#include <string>

#include "core/json_reader.hpp"

namespace omniloc::harness {

/// JSON Schema (draft 2020-12) of a scenario file.
Json scenario_schema();

/// docs/localizers.md: every localizer's parameters, the vision front end's, the sensor noise keys
/// and the named noise profiles, as Markdown tables generated from scenario_schema().
std::string parameter_reference();

}  // namespace omniloc::harness
