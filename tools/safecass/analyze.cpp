// `safecass analyze SYSTEM [--fmea] [--fault-trees] [--gsn] [--format text|csv|json] ...`
// (docs/analyze.md).

#include <CLI/CLI.hpp>
#include <cstdio>

#include "commands.hpp"
#include "safecass/analyze/analyze.hpp"
#include "safecass/filters/registry.hpp"

namespace safecass::tools {

namespace {

struct AnalyzeArgs {
  analyze::AnalyzeOptions options;
  std::vector<std::string> tops;
  bool fmea = false, trees = false, gsn = false, strict = false;
  std::string format = "text";
  std::string mef;   ///< --mef FILE: the fault trees as given to SCRAM
  std::string html;  ///< --html FILE: the report
  std::string pdf;   ///< --pdf FILE: the report printed by Chromium
  std::string chromium = "chromium";
};

int run_analyze(AnalyzeArgs& args) {
  for (const std::string& t : args.tops) {
    auto top = analyze::parse_top(t);
    if (!top) {
      std::fprintf(stderr, "safecass analyze: --top %s\n", top.error().message.c_str());
      return 2;
    }
    args.options.tops.push_back(*top);
  }
  const bool all = !args.fmea && !args.trees && !args.gsn;
  args.options.fault_trees = all || args.trees || !args.mef.empty();
  auto built = analyze::build_analysis(args.options, builtin_filters());
  if (!built) {
    for (const spec::Diagnostic& d : built.error()) std::fprintf(stderr, "%s\n", spec::format(d).c_str());
    std::fprintf(stderr, "safecass analyze: nothing analysed (%zu error%s)\n", built.error().size(),
                 built.error().size() == 1 ? "" : "s");
    return 2;
  }
  const analyze::Analysis& a = *built;
  for (const spec::Diagnostic& d : a.trace.notes) std::fprintf(stderr, "%s\n", spec::format(d).c_str());
  std::string text;
  if (args.format == "json") {
    text = analyze::analysis_json(a);
  } else if (args.format == "csv") {
    text = analyze::fmea_csv(a);
  } else {
    if (all || args.fmea) text += analyze::fmea_text(a);
    if (all || args.trees) text += analyze::fault_trees_text(a);
    if (all || args.gsn) text += analyze::safety_case_text(a);
  }
  std::fwrite(text.data(), 1, text.size(), stdout);
  if (!args.mef.empty() && !write_output("analyze", args.mef, a.trees.mef)) return 2;
  if (!args.html.empty() || !args.pdf.empty()) {
    const std::string html = args.html.empty() ? args.pdf + ".html" : args.html;
    if (!write_output("analyze", html, analyze::render_analysis_page(a, report_date()))) return 2;
    if (!args.pdf.empty()) {
      auto printed = analyze::print_pdf(html, args.pdf, args.chromium);
      if (args.html.empty()) std::remove(html.c_str());
      if (!printed) {
        std::fprintf(stderr, "safecass analyze: %s\n", printed.error().message.c_str());
        return 2;
      }
      std::fprintf(stderr, "safecass analyze: report printed to %s\n", args.pdf.c_str());
    }
    if (!args.html.empty()) std::fprintf(stderr, "safecass analyze: report written to %s\n", args.html.c_str());
  }
  if (a.has_error_gap()) return 1;
  if (args.strict && a.gap_count(trace::Severity::Warning) != 0) return 1;
  return 0;
}

}  // namespace

void add_analyze_command(CLI::App& app, int& code) {
  auto args = std::make_shared<AnalyzeArgs>();
  auto* cmd = app.add_subcommand(
      "analyze", "The FMEA, the fault trees (SCRAM) and the GSN safety case, derived from the specification");
  cmd->add_option("SYSTEM", args->options.system, "system file")->required();
  cmd->add_flag("--fmea", args->fmea, "the FMEA (default: all three)");
  cmd->add_flag("--fault-trees", args->trees, "the fault trees and their minimal cut sets (default: all three)");
  cmd->add_flag("--gsn", args->gsn, "the GSN safety case (default: all three)");
  cmd->add_option("--format", args->format, "text (default), csv (the FMEA's rows) or json (everything)")
      ->check(CLI::IsMember({"text", "csv", "json"}));
  cmd->add_option("--scenarios,-s", args->options.scenarios, "scenarios to run as test evidence");
  cmd->add_option("--verify", args->options.verify_json, "the output of `safecass verify --json`: what is proved");
  cmd->add_option("--top", args->tops, "another top event, ADDRESS=LEVEL (e.g. SERVO=Error); repeatable")
      ->allow_extra_args(false);
  cmd->add_option("--order", args->options.order, "the largest cut set computed, 1 to 6 (default 3)")
      ->check(CLI::Range(1, 6));
  cmd->add_option("--mef", args->mef, "write the fault trees in the Open-PSA MEF to this file");
  cmd->add_option("--html", args->html, "write the report (one self-contained page, printable to PDF) to this file");
  cmd->add_option("--pdf", args->pdf, "print the report to this PDF file with headless Chromium");
  cmd->add_option("--chromium", args->chromium, "Chromium's executable for --pdf (default: chromium)");
  cmd->add_option("--scram", args->options.scram, "SCRAM's executable (default: scram)");
  cmd->add_flag("--strict", args->strict, "exit 1 on a gap of warning severity too");
  cmd->callback([args, &code] { code = run_analyze(*args); });
}

}  // namespace safecass::tools
