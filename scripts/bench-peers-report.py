#!/usr/bin/env python3
"""Composes build/bench-peers.json from the parts scripts/bench-peers measured, and prints the table.

    bench-peers-report.py WORK_DIR OUT.json      (environment: QUICK=0|1, FAILED="part ...")

Exits 1 when a top-level figure the benchmark promises is missing (a part failed or wrote nothing).
"""
import json
import os
import sys

REQUIRED = [
    "visibility_p50_ratio_vs_icestorm_sender_thread",
    "visibility_p99_ratio_vs_icestorm_sender_thread",
    "visibility_p99_ratio_vs_icestorm",
    "visibility_speedup_vs_ros_diagnostics_default",
    "supervisor_cpu_ratio_vs_aggregator",
    "event_ns_ratio_vs_msm",
    "detection_cpu_percent",
    "detection_p99_us",
]


def load(work, name):
    try:
        with open(os.path.join(work, name + ".json"), encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def rounds_of(work, name):
    """The rounds of part `name` (NAME_r1.json, NAME_r2.json, ...), in order."""
    rounds = []
    for n in range(1, 100):
        part = load(work, f"{name}_r{n}")
        if part is None:
            break
        rounds.append(part)
    return rounds


def median(values):
    values = sorted(v for v in values if v is not None)
    return None if not values else values[(len(values) - 1) // 2]


def median_latency(work, name):
    """A latency part measured in rounds: its p50 and p99 each the median of the rounds' (every
    round's pair in "rounds"), its max the largest; the part's single run when it has no rounds."""
    rounds = rounds_of(work, name)
    if not rounds:
        return load(work, name)
    out = dict(rounds[0])
    out["p50_us"] = median(r.get("p50_us") for r in rounds)
    out["p99_us"] = median(r.get("p99_us") for r in rounds)
    out["max_us"] = max((r["max_us"] for r in rounds if r.get("max_us") is not None), default=None)
    out["rounds"] = [[r.get("p50_us"), r.get("p99_us")] for r in rounds]
    return out


def median_round(work, name):
    """The round of part `name` (NAME_r1.json, NAME_r2.json, ...) with the median CPU per update,
    with every round's figure in "rounds"; the part's single run (NAME.json) when it has no rounds."""
    rounds = rounds_of(work, name)
    usable = sorted((r for r in rounds if r.get("cpu_s_per_10k_updates") is not None),
                    key=lambda r: r["cpu_s_per_10k_updates"])
    if not usable:
        return load(work, name)
    chosen = dict(usable[(len(usable) - 1) // 2])
    chosen["rounds"] = [r.get("cpu_s_per_10k_updates") for r in rounds]
    # What a process holds for the items is measured from its start: the first round's (the
    # aggregator runs on through the rounds, holding them already).
    if "bytes_per_item" in rounds[0]:
        chosen["bytes_per_item"] = rounds[0]["bytes_per_item"]
    return chosen


def rounds_text(part):
    """ " (median of rounds a / b / c)" for a part measured in rounds."""
    rounds = part.get("rounds") or []
    if len(rounds) < 2:
        return ""
    return " (median of rounds " + " / ".join("—" if r is None else f"{r:.4f}" for r in rounds) + ")"


def ratio(a, b):
    if a is None or b is None or b == 0:
        return None
    return a / b


def get(part, key):
    return None if part is None else part.get(key)


def gbench(part, name):
    """(cpu ns per iteration, the entry) of a Google Benchmark result: the median when repeated."""
    if part is None:
        return None, None
    entries = part.get("benchmarks", [])
    # A repeated run: its median; else the one run. run_name drops "_median" but keeps
    # "/iterations:N", which a name given without it also matches.
    for median in (True, False):
        for e in entries:
            run = e.get("run_name", e.get("name", ""))
            if run != name and not run.startswith(name + "/iterations:"):
                continue
            if median != (e.get("run_type") == "aggregate" and e.get("aggregate_name") == "median"):
                continue
            if not median and e.get("run_type", "iteration") != "iteration":
                continue
            scale = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}[e.get("time_unit", "ns")]
            return e["cpu_time"] * scale, e
    return None, None


def main():
    work, out = sys.argv[1], sys.argv[2]
    quick = os.environ.get("QUICK", "0") == "1"
    failed = os.environ.get("FAILED", "").split()

    vis = {
        "safecass_over_icestorm": median_latency(work, "safecass_visibility"),
        "icestorm_raw": load(work, "icestorm_visibility"),
        "icestorm_raw_tls": load(work, "icestorm_tls_visibility"),
        "icestorm_raw_tls_sender_thread": median_latency(work, "icestorm_tls_sender_visibility"),
        "roscpp_raw": load(work, "ros_visibility"),
        "ros_diagnostics_default": load(work, "diag_default_visibility"),
        "ros_diagnostics_fastest": load(work, "diag_fastest_visibility"),
        "safecass_dds_node": load(work, "dds_visibility"),
    }
    watch = {"safecass_supervisor": load(work, "safecass_watch"),
             "safecass_supervisor_states_only": median_round(work, "safecass_watch_states"),
             "ros_diagnostic_aggregator": median_round(work, "aggregator_watch")}
    sm = load(work, "state_machines")
    safecass_ns, _ = gbench(sm, "BM_PeerSafecassEvent")
    msm_ns, _ = gbench(sm, "BM_PeerMsmEvent")
    chart_ns, _ = gbench(sm, "BM_PeerStatechartEvent")
    per_event = lambda ns: None if ns is None else ns / 2.0  # one iteration: onset + completion
    machines = {
        "safecass_ns_per_event": per_event(safecass_ns),
        "boost_msm_ns_per_event": per_event(msm_ns),
        "boost_statechart_ns_per_event": per_event(chart_ns),
    }
    detection = load(work, "detection")
    scale_part = load(work, "scale")
    _, rate_entry = gbench(scale_part, "BM_ScaleEventRate/1000")
    _, memory_entry = gbench(scale_part, "BM_ScaleMemory/1000")
    scale = {
        "components": 1000,
        "events_per_s": None if rate_entry is None else rate_entry.get("items_per_second"),
        "bytes_per_component": None if memory_entry is None else memory_entry.get("bytes_per_component"),
        "aggregator_bytes_per_item": get(watch["ros_diagnostic_aggregator"], "bytes_per_item"),
    }
    scale["memory_ratio_vs_aggregator_item"] = ratio(scale["bytes_per_component"], scale["aggregator_bytes_per_item"])

    # SAFECASS runs its bus over mutual TLS (members only at the broker): its transport's floor is
    # raw IceStorm over the same TLS; the plain-TCP ratios are reported beside.
    sc, ice, ros = vis["safecass_over_icestorm"], vis["icestorm_raw_tls"], vis["roscpp_raw"]
    ice_plain = vis["icestorm_raw"]
    ice_sender = vis["icestorm_raw_tls_sender_thread"]
    dd, df = vis["ros_diagnostics_default"], vis["ros_diagnostics_fastest"]
    dds = vis["safecass_dds_node"]
    sup, agg = watch["safecass_supervisor"], watch["ros_diagnostic_aggregator"]
    sup_states = watch["safecass_supervisor_states_only"]
    result = {
        # The fair peer: raw IceStorm published from a sender thread (DESIGN §7: SAFECASS's control
        # loop never touches the network); the ratios to publishing from the faulting thread follow.
        "visibility_p50_ratio_vs_icestorm_sender_thread": ratio(get(sc, "p50_us"), get(ice_sender, "p50_us")),
        "visibility_p99_ratio_vs_icestorm_sender_thread": ratio(get(sc, "p99_us"), get(ice_sender, "p99_us")),
        "visibility_p99_ratio_vs_icestorm": ratio(get(sc, "p99_us"), get(ice, "p99_us")),
        "visibility_speedup_vs_ros_diagnostics_default": ratio(get(dd, "p50_us"), get(sc, "p50_us")),
        "supervisor_cpu_ratio_vs_aggregator": ratio(get(sup, "cpu_s_per_10k_updates"), get(agg, "cpu_s_per_10k_updates")),
        "event_ns_ratio_vs_msm": ratio(machines["safecass_ns_per_event"], machines["boost_msm_ns_per_event"]),
        "detection_cpu_percent": get(detection, "cpu_percent"),
        "detection_p99_us": get(detection, "p99_us"),
        # More ratios, same definitions.
        "visibility_p50_ratio_vs_icestorm": ratio(get(sc, "p50_us"), get(ice, "p50_us")),
        "visibility_p99_ratio_vs_icestorm_plain_tcp": ratio(get(sc, "p99_us"), get(ice_plain, "p99_us")),
        "visibility_p50_ratio_vs_icestorm_plain_tcp": ratio(get(sc, "p50_us"), get(ice_plain, "p50_us")),
        "icestorm_tls_p50_ratio_vs_plain_tcp": ratio(get(ice, "p50_us"), get(ice_plain, "p50_us")),
        "visibility_p99_ratio_vs_roscpp": ratio(get(sc, "p99_us"), get(ros, "p99_us")),
        "visibility_speedup_vs_ros_diagnostics_fastest": ratio(get(df, "p50_us"), get(sc, "p50_us")),
        # The supervisor following the service states only (--states-only), as the aggregator does.
        "supervisor_states_only_cpu_ratio_vs_aggregator": ratio(get(sup_states, "cpu_s_per_10k_updates"),
                                                                get(agg, "cpu_s_per_10k_updates")),
        "event_ns_ratio_vs_statechart": ratio(machines["safecass_ns_per_event"], machines["boost_statechart_ns_per_event"]),
        "scale_events_per_s": scale["events_per_s"],
        # SAFECASS on ROS 2 (safecass_dds_node's bridge): a driver's sample → a /diagnostics reader.
        "dds_node_visibility_p50_us": get(dds, "p50_us"),
        "dds_node_visibility_p99_us": get(dds, "p99_us"),
        "memory_ratio_vs_aggregator_item": scale["memory_ratio_vs_aggregator_item"],
        "visibility": vis,
        "watching": watch,
        "state_machines": machines,
        "detection": detection,
        "scale": scale,
    }
    period_us = get(detection, "period_us") or 1000.0
    targets = [
        ("visibility_p50_ratio_vs_icestorm_sender_thread", "<=", 1.15),
        ("visibility_p99_ratio_vs_icestorm_sender_thread", "<=", 1.3),
        ("visibility_p99_ratio_vs_icestorm", "<=", 1.2),
        ("visibility_speedup_vs_ros_diagnostics_default", ">=", 1000.0),
        ("supervisor_cpu_ratio_vs_aggregator", "<=", 0.01),
        ("event_ns_ratio_vs_msm", "<=", 2.0),
        ("detection_cpu_percent", "<=", 5.0),
        ("detection_p99_us", "<=", 1000.0 + period_us),
    ]
    result["targets"] = {
        key: {"target": f"{op} {bound:g}", "value": result[key],
              "met": None if result[key] is None else (result[key] <= bound if op == "<=" else result[key] >= bound)}
        for key, op, bound in targets
    }
    try:
        with open("/proc/loadavg", encoding="ascii") as f:
            load_avg = f.read().split()[:3]
    except OSError:
        load_avg = []
    result["machine"] = {"cores": os.cpu_count(), "load_average_at_end": load_avg}
    result["quick"] = quick
    result["failed_parts"] = failed
    with open(out, "w", encoding="utf-8") as f:
        json.dump(result, f, indent=2)
        f.write("\n")

    def fmt(v, unit="", digits=1):
        if v is None:
            return "—"
        if isinstance(v, float) and abs(v) >= 1e4:
            return f"{v:,.0f}{unit}"
        return f"{v:.{digits}f}{unit}"

    def lat(p):
        if p is None:
            return "—"
        text = f"{fmt(p.get('p50_us'))} / {fmt(p.get('p99_us'))} / {fmt(p.get('max_us'))} µs (n={p.get('samples')}"
        rounds = p.get("rounds") or []
        if len(rounds) < 2:
            return text + ")"
        return (text + f" per round, the medians of each round's p50 / p99: "
                + ", ".join(f"{fmt(a, '', 0)} / {fmt(b, '', 0)}" for a, b in rounds) + ")")

    rows = [
        ("visibility SAFECASS over IceStorm, TLS (p50/p99/max)", lat(sc)),
        ("visibility raw IceStorm, same TLS, from a sender thread", lat(ice_sender)),
        ("visibility raw IceStorm, same TLS, from the faulting thread", lat(ice)),
        ("visibility raw IceStorm, plain TCP", lat(ice_plain)),
        ("visibility raw roscpp", lat(ros)),
        ("visibility ROS diagnostics, defaults", lat(dd)),
        ("visibility ROS diagnostics, fastest", lat(df)),
        ("visibility SAFECASS on ROS 2 (DDS): sample → /diagnostics", lat(dds)),
        ("supervisor CPU s / 10k updates, RSS", "—" if sup is None else
         f"{fmt(sup.get('cpu_s_per_10k_updates'), '', 4)} s, {fmt(sup.get('rss_bytes', 0) / 1e6)} MB"),
        ("supervisor --states-only CPU s / 10k updates, RSS", "—" if sup_states is None else
         f"{fmt(sup_states.get('cpu_s_per_10k_updates'), '', 4)} s, {fmt(sup_states.get('rss_bytes', 0) / 1e6)} MB"
         + rounds_text(sup_states)),
        ("aggregator CPU s / 10k updates, RSS", "—" if agg is None else
         f"{fmt(agg.get('cpu_s_per_10k_updates'), '', 4)} s, {fmt(agg.get('rss_bytes', 0) / 1e6)} MB"
         + rounds_text(agg)),
        ("supervisor --states-only / aggregator, CPU per update",
         fmt(result["supervisor_states_only_cpu_ratio_vs_aggregator"], "", 2)),
        ("ns per event: SAFECASS / MSM / Statechart",
         " / ".join(fmt(machines[k]) for k in ("safecass_ns_per_event", "boost_msm_ns_per_event",
                                                 "boost_statechart_ns_per_event"))),
        ("detection 1,000 signals at 1 kHz: CPU %, p99", f"{fmt(result['detection_cpu_percent'], ' %', 2)}, "
                                                          f"{fmt(result['detection_p99_us'], ' µs')}"),
        ("1,000 components: events/s, bytes/component", f"{fmt(scale['events_per_s'])}, {fmt(scale['bytes_per_component'], '', 0)}"
                                                         f" (aggregator: {fmt(scale['aggregator_bytes_per_item'], '', 0)} per item)"),
    ]
    print()
    print("SAFECASS and its peers" + (" (--quick: short runs, not the issue's figures)" if quick else ""))
    width = max(len(r[0]) for r in rows)
    for name, value in rows:
        print(f"  {name:<{width}}  {value}")
    print()
    for key, t in result["targets"].items():
        met = "—" if t["met"] is None else ("met" if t["met"] else "MISSED")
        print(f"  {key:<{max(len(k) for k in result['targets'])}}  {fmt(t['value'], '', 4):>12}  target {t['target']:<8}  {met}")
    print(f"\nbench-peers: results in {out} (machine: {os.cpu_count()} cores, load average {' '.join(load_avg)})")
    missing = [k for k in REQUIRED if result.get(k) is None]
    if missing:
        print("bench-peers: missing figures: " + ", ".join(missing), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
