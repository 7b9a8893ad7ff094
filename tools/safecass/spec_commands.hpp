#pragma once
// `safecass validate` and `safecass schema`.

#include <string>
#include <vector>

namespace safecass::tools {

/// Loads and validates each file (system or component), printing every diagnostic as
/// "file:line:col: error|warning: message [pointer]" (or, with `json_output`, one JSON object
/// per line, then a summary object), and a final "N errors, M warnings" line.
/// Returns 0 when there is no error, 1 when there are errors, 2 when a file cannot be read.
int run_validate(const std::vector<std::string>& files, bool json_output, bool verbose = false);

/// Prints the JSON Schema of specification files (built-in filter types). Returns 0.
int run_schema();

}  // namespace safecass::tools

using safecass::tools::run_schema;
using safecass::tools::run_validate;
