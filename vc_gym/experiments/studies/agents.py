"""Learned agents against the scripted one on the same kidnappings (``vc-gym experiment agents``).

Every agent runs the homing experiment (:func:`~vc_gym.experiments.studies.homing.run_homing`)
with the same learning seeds, the same saved atlases (learned once, by the first agent's
run) and the same kidnapping seeds, so episode ``i`` of learning seed ``s`` starts from
the same pose for every agent. The results hold each agent's figures (success within
30 cm, mean and median stop distance, stops more than 50 cm from home, timeouts, mean
homing time), the learned agents' mean ± standard deviation over agents (e.g. one per
training seed, ``vc-gym train --seeds``), and a paired comparison with the scripted
agent over the same kidnappings: in how many a learned agent stopped at least as close
to home and was at least as fast, the mean differences, and the ratio of the mean homing
times. ``agents.png`` shows every agent's stop distances.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from vc_gym.agents.learned import PRETRAINED_MODEL, LearnedHomingAgent
from vc_gym.experiments.episode import canonical_homing_mode, default_homing_mode
from vc_gym.experiments.studies import get_experiment
from vc_gym.experiments.studies.common import ExperimentOptions
from vc_gym.experiments.studies.kidnapping import PAPER_MEAN_CM, PAPER_STD_CM, mean_std
from vc_gym.jobs.output import check_out_dir, new_figure, save_figure, write_json
from vc_gym.localization import tracker_label

__all__ = ["agent_list", "run_agents", "summary_lines"]


def agent_list(agent: str | Sequence[str]) -> list[str]:
    """The agents of ``agent``: a comma-separated string or a sequence, at least two,
    ``"scripted"`` among them (it is what the learned agents are compared with)."""
    names = [a.strip() for a in agent.split(",")] if isinstance(agent, str) else list(agent)
    if any(not isinstance(a, str) or not a for a in names):
        raise ValueError(f"agents must be non-empty names or paths, got {agent!r}")
    if "scripted" not in names or len(names) < 2 or len(set(names)) != len(names):
        raise ValueError(
            "agents must name 'scripted' and at least one learned agent ('pretrained' or "
            f"DIR/model.zip), each once, e.g. scripted,pretrained; got {agent!r}"
        )
    for a in names:
        if a not in ("scripted", "pretrained") and not Path(a).is_file():
            raise ValueError(f"{a}: no such model file (expected DIR/model.zip from train)")
    return names


def _learned_mode(agents: Sequence[str], allow_imports: bool) -> str:
    """The homing mode the learned ``agents``' training places were learned in (one for
    all of them, else a ``ValueError`` asking for ``mode``)."""
    modes = {
        a: default_homing_mode(LearnedHomingAgent(_model(a), allow_imports))
        for a in agents
        if a != "scripted"
    }
    if len(set(modes.values())) != 1:
        raise ValueError(
            f"the learned agents trained in places of different homing modes ({modes}); "
            "name the mode to compare them in"
        )
    return next(iter(modes.values()))


def _model(agent: str) -> str:
    return str(PRETRAINED_MODEL) if agent == "pretrained" else agent


def _labels(agents: Sequence[str]) -> list[str]:
    labels: list[str] = []
    for a in agents:
        base = a if a in ("scripted", "pretrained") else Path(a).resolve().parent.name
        label, k = base, 2
        while label in labels:
            label, k = f"{base}-{k}", k + 1
        labels.append(label)
    return labels


def run_agents(
    out_dir: str | os.PathLike,
    opts: ExperimentOptions | None = None,
    agent: str | Sequence[str] = "scripted,pretrained",
    tracker: Any = None,
    seeds: Sequence[int] | None = None,
    episodes: int | None = None,
    learn_time_s: float | None = None,
    max_homing_s: float | None = None,
    mode: str | None = None,
    allow_imports: bool = False,
) -> dict[str, Any]:
    """Run the homing experiment for every agent on the same kidnappings.

    Parameters
    ----------
    out_dir : path-like
        The run folder: one homing run per agent in ``DIR/<label>`` (resumable) and
        ``DIR/results.json``, ``DIR/agents.png``.
    opts : ExperimentOptions
        Seed, size, backend, progress (``--atlas DIR`` is passed to the first run).
    agent : str or sequence of str
        ``"scripted"`` and learned agents (``"pretrained"`` or ``DIR/model.zip``),
        comma-separated or a list. A learned agent's label is its folder's name.
    tracker, seeds, episodes, learn_time_s, max_homing_s, mode, allow_imports
        As :func:`~vc_gym.experiments.studies.homing.run_homing`. Every agent homes in
        the same places, learned the ``mode``'s way (default: the way the learned
        agents' training places were learned, which must be one mode for all of them),
        and the scripted agent homes with that mode's policy and tracker: the learned
        agents are compared with the scripted agent of their own mode.

    Returns
    -------
    dict
        The results written to ``results.json``.
    """
    opts = opts or ExperimentOptions()
    agents = agent_list(agent)
    mode = canonical_homing_mode(_learned_mode(agents, allow_imports) if mode is None else mode)
    labels = _labels(agents)
    out = check_out_dir(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    order = [agents.index("scripted")] + [i for i, a in enumerate(agents) if a != "scripted"]
    per_agent: dict[str, dict[str, Any]] = {}
    atlas_dir = opts.atlas_dir
    run_homing = get_experiment("homing").runner()
    for i in order:
        sub = out / labels[i]
        if opts.progress:
            print(f"agents: {labels[i]} -> {sub}")
        results = run_homing(
            sub,
            replace(opts, atlas_dir=atlas_dir),
            agent=agents[i],
            tracker=tracker,
            seeds=seeds,
            episodes=episodes,
            learn_time_s=learn_time_s,
            max_homing_s=max_homing_s,
            field=False,
            mode=mode,
            allow_imports=allow_imports,
        )
        atlas_dir = sub / "atlases"  # every later agent homes in the places learned here
        per_agent[labels[i]] = results
    summary = _summarise(per_agent, labels[order[0]], [labels[i] for i in order[1:]])
    summary["settings"] = {
        "agents": [labels[i] for i in order],
        "tracker": per_agent[labels[order[0]]]["settings"]["tracker"],
        "seeds": per_agent[labels[order[0]]]["settings"]["seeds"],
        "episodes_per_seed": per_agent[labels[order[0]]]["settings"]["episodes_per_seed"],
        "mode": mode,
        "base_seed": opts.seed,
    }
    _plot(out / "agents.png", per_agent, summary)
    write_json(out / "results.json", summary)
    return summary


def _key(e: dict[str, Any]) -> tuple[int, int]:
    return int(e["learning_seed"]), int(e["seed"])


def _summarise(
    per_agent: dict[str, dict[str, Any]], scripted: str, learned: list[str]
) -> dict[str, Any]:
    rows = {}
    for label, res in per_agent.items():
        o = res.get("overall", {})
        rows[label] = {
            k: o.get(k)
            for k in (
                "episodes",
                "success_rate",
                "mean_stop_distance_cm",
                "median_stop_distance_cm",
                "mean_stop_offset_cm",
                "std_stop_offset_cm",
                "far_stops",
                "timed_out",
                "mean_homing_time_s",
            )
        }
        rows[label]["per_seed"] = [
            {
                k: p.get(k)
                for k in ("seed", "success_rate", "mean_stop_distance_cm", "mean_homing_time_s")
            }
            for p in res.get("per_seed", [])
        ]
    base = {_key(e): e for e in per_agent[scripted].get("per_episode", [])}
    paired = {}
    for label in learned:
        eps = [e for e in per_agent[label].get("per_episode", []) if _key(e) in base]
        if not eps:
            continue
        d_l = np.array([e["home_error_m"] for e in eps])
        d_s = np.array([base[_key(e)]["home_error_m"] for e in eps])
        t_l = np.array([e["sim_time_s"] for e in eps])
        t_s = np.array([base[_key(e)]["sim_time_s"] for e in eps])
        paired[label] = {
            "episodes": len(eps),
            "at_least_as_close": int(np.sum(d_l <= d_s + 1e-9)),
            "mean_distance_difference_cm": round(float(np.mean(d_l - d_s)) * 100, 1),
            "at_least_as_fast": int(np.sum(t_l <= t_s + 1e-9)),
            "mean_homing_time_difference_s": round(float(np.mean(t_l - t_s)), 1),
            "homing_time_ratio": round(float(np.mean(t_l) / np.mean(t_s)), 3),
        }
    out: dict[str, Any] = {
        "paper": {
            "mean_stop_offset_cm": list(PAPER_MEAN_CM),
            "std_stop_offset_cm": list(PAPER_STD_CM),
            "episodes": 33,
        },
        "agents": rows,
        "paired_with_scripted": paired,
    }
    figures = [rows[a] for a in learned if rows[a]["episodes"]]
    if figures:
        out["learned_over_agents"] = {
            "agents": len(figures),
            "success_rate": mean_std([r["success_rate"] for r in figures]),
            "mean_stop_distance_cm": mean_std([r["mean_stop_distance_cm"] for r in figures]),
            "far_stops": mean_std([r["far_stops"] for r in figures]),
            "timed_out": mean_std([r["timed_out"] for r in figures]),
            "mean_homing_time_s": mean_std([r["mean_homing_time_s"] for r in figures]),
        }
    return out


def _plot(path: Path, per_agent: dict[str, dict[str, Any]], summary: dict[str, Any]) -> None:
    labels = summary["settings"]["agents"]
    dists = [  # cm, floored at 1 cm for the log axis
        [max(1.0, 100 * e["home_error_m"]) for e in per_agent[a].get("per_episode", [])]
        for a in labels
    ]
    fig = new_figure(figsize=(1.6 * len(labels) + 3, 4), layout="constrained")
    ax = fig.subplots()
    rng = np.random.default_rng(0)  # jitter of the dots only
    for k, d in enumerate(dists):
        ax.plot(k + rng.uniform(-0.15, 0.15, len(d)), d, ".", ms=4, alpha=0.6)
        if d:
            ax.plot([k - 0.3, k + 0.3], [np.mean(d)] * 2, color="k", lw=2)
    ax.axhline(30, ls="--", color="0.5", label="success radius (30 cm)")
    ax.axhline(
        float(np.hypot(*PAPER_MEAN_CM)), ls=":", color="tab:red", label="paper: |mean offset|"
    )
    rows = summary["agents"]
    ax.set_xticks(
        range(len(labels)),
        [
            f"{a}\n{rows[a]['success_rate']:.0%}, {rows[a]['mean_stop_distance_cm']:.0f} cm"
            if rows[a]["episodes"]
            else a
            for a in labels
        ],
        fontsize=8,
    )
    ax.set_ylabel("stop distance from home (cm, log); bar: mean")
    ax.set_yscale("log")
    ax.set_ylim(1, None)
    s = summary["settings"]
    ax.set_title(
        f"same {len(s['seeds'])} learning seeds × {s['episodes_per_seed']} kidnappings, "
        f"{tracker_label(s['tracker'])} tracker",
        fontsize=10,
    )
    ax.legend(fontsize=7, loc="upper right")
    save_figure(fig, path, dpi=100)


def summary_lines(results: dict[str, Any]) -> list[str]:
    """Each agent's figures, the learned agents' spread and the paired comparison."""
    lines = []
    for label, r in results.get("agents", {}).items():
        if not r["episodes"]:
            lines.append(f"{label}: no episode finished")
            continue
        lines.append(
            f"{label}: {r['episodes']} kidnappings, success {r['success_rate']:.0%}, mean "
            f"distance {r['mean_stop_distance_cm']} cm (median {r['median_stop_distance_cm']} "
            f"cm), mean offset {r['mean_stop_offset_cm']} cm, std {r['std_stop_offset_cm']} cm, "
            f"{r['far_stops']} stops > 50 cm, {r['timed_out']} timed out, mean homing time "
            f"{r['mean_homing_time_s']} s"
        )
    for label, p in results.get("paired_with_scripted", {}).items():
        lines.append(
            f"{label} vs scripted: at least as close in {p['at_least_as_close']}/"
            f"{p['episodes']} kidnappings, mean distance {p['mean_distance_difference_cm']:+} cm; "
            f"at least as fast in {p['at_least_as_fast']}/{p['episodes']}, mean homing time "
            f"{p['mean_homing_time_difference_s']:+} s ({p['homing_time_ratio']:.2f} × "
            "the scripted agent's)"
        )
    lo = results.get("learned_over_agents")
    if lo:
        s, d, t = lo["success_rate"], lo["mean_stop_distance_cm"], lo["mean_homing_time_s"]
        lines.append(
            f"learned agents ({lo['agents']}): success {s[0]:.0%} ± {s[1]:.0%}, mean distance "
            f"{d[0]:.1f} ± {d[1]:.1f} cm, mean homing time {t[0]:.1f} ± {t[1]:.1f} s "
            "(mean ± std over agents)"
        )
    lines.append("paper: mean stop offset (-22, 12) cm, std (17, 15) cm over 33 kidnappings")
    return lines
