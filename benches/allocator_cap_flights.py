"""Every builtin scenario flown with the default allocator uncapped and with its walk capped at
2 (the default since issue 59) and at 0 rounds (the scenario field ``allocator_max_rounds``).

Prints a Markdown table of the flights that differ: RMS position error (m), largest tilt (rad),
largest force error ``e_f`` (N) and the scenario's verdict, uncapped / cap 2 / cap 0.

Run after building the wheel: ``.venv/bin/python benches/allocator_cap_flights.py``.
"""

from __future__ import annotations

import tvmd.sim as sim

CAPS = ("\"uncapped\"", 2, 0)


def flight(toml: str) -> tuple[float, float, float, bool]:
    s = sim.run(toml=toml).summary
    return (s["metrics"]["position"]["rms"], s["max_tilt"], s["max_e_f"], s["verdict"]["success"])


def main() -> None:
    print("| scenario | uncapped | cap 2 | cap 0 |")
    print("|---|---|---|---|")
    same = []
    for name in sim.builtin_scenarios():
        # The cap a scenario names (the paper's name "uncapped") gives way to each of CAPS.
        lines = sim.scenario_toml(name).splitlines(keepends=True)
        base = "".join(l for l in lines if not l.startswith("allocator_max_rounds"))
        runs = [flight(f"allocator_max_rounds = {cap}\n" + base) for cap in CAPS]
        if all(r == runs[0] for r in runs):
            same.append(name)
            continue
        cells = [f"{p:.4f} / {t:.3f} / {e:.2g} / {'ok' if ok else 'fails'}" for p, t, e, ok in runs]
        print(f"| {name} | " + " | ".join(cells) + " |")
    print(f"\nIdentical uncapped and capped ({len(same)}): {', '.join(same)}")


if __name__ == "__main__":
    main()
