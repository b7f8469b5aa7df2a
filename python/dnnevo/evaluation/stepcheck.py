"""The time-step check: a champion judged again on the same fresh conditions with a finer Euler
step and with RK4, so that a behaviour that lives only in the integrator's error shows itself.

Evolution integrates with a coarse Euler step (the paper's dt = 0.1), and selection rewards
whatever works at that step, including behaviour the step itself creates. A result belongs to
the network's equation only if it survives a finer step. :func:`step_check` re-judges a
champion with

- ``dt/10``: the run's method with a step :data:`FINER` times shorter, each time step kept as
  long (``substeps`` times :data:`FINER`), so the 1-D world, which moves at every integration
  step, is refined too;
- ``rk4``: the fourth-order Runge-Kutta method at the run's own step (when the run used Euler),

each on exactly the conditions of the run's own step (same seed), so the comparison is paired.
A champion is a **step artefact** when a rate that does not fail at the run's step fails at
either finer integration.

>>> from dnnevo.config import EvolutionConfig
>>> with_dt(EvolutionConfig(), 0.01).integrator
IntegratorConfig(method='euler', dt=0.01, substeps=100)
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from collections.abc import Callable
from typing import Any

from dnnevo import _core
from dnnevo.config import EvolutionConfig
from dnnevo.errors import ConfigError
from dnnevo.evaluation.assessment import Assessment

__all__ = ["FINER", "Judge", "StepCheck", "finer_configs", "step_check", "with_dt"]

FINER: int = _core.STEP_CHECK_FINER
"""How many times shorter the check's Euler step is than the run's (the Rust core's
``STEP_CHECK_FINER``, which ``champion_step_check`` uses during a run too)."""


def with_dt(config: EvolutionConfig, dt: float, name: str = "dt") -> EvolutionConfig:
    """``config`` integrated with step ``dt``, as many steps per time step as keep a time step
    ``integrator.dt * integrator.substeps`` long; a ``dt`` that does not divide it is an error
    that calls it ``name``."""
    if not (isinstance(dt, int | float) and math.isfinite(dt) and dt > 0):
        raise ConfigError(f"{name} is {dt}; it must be a number > 0")
    step = config.integrator.dt * config.integrator.substeps
    substeps = round(step / dt)
    if substeps < 1 or not math.isclose(substeps * dt, step, rel_tol=1e-9):
        raise ConfigError(f"{name} {dt} does not divide the run's time step of {step:g} "
                          f"(dt {config.integrator.dt:g} x {config.integrator.substeps} steps)")
    integrator = dataclasses.replace(config.integrator, dt=dt, substeps=substeps)
    return dataclasses.replace(config, integrator=integrator)


def finer_configs(config: EvolutionConfig) -> dict[str, EvolutionConfig]:
    """The integrations a check compares with the run's own, by name: the run's method at a step
    :data:`FINER` times shorter, and RK4 at the run's step when the run integrated with Euler."""
    i = config.integrator
    out = {f"dt/{FINER}": with_dt(config, i.dt / FINER)}
    if i.method != "rk4":
        out["rk4"] = dataclasses.replace(config, integrator=dataclasses.replace(i, method="rk4"))
    return out


@dataclass(frozen=True)
class StepCheck:
    """A champion judged at the run's step (:attr:`base`) and at finer ones (:attr:`checks`)."""

    base: Assessment
    checks: dict[str, Assessment]
    """Each finer integration's assessment, by name (see :func:`finer_configs`)."""
    integrators: dict[str, dict[str, Any]]
    """The integrator of the run's step (``"run"``) and of each check."""

    @property
    def artefacts(self) -> list[str]:
        """``"<check>: <rate>"`` for each rate that does not fail at the run's step and fails at
        a check."""
        out = []
        for name, check in self.checks.items():
            for b, c in zip(self.base.rates, check.rates, strict=True):
                if b.verdict in ("pass", "undecided") and c.verdict == "fail":
                    out.append(f"{name}: {b.name}")
        return out

    @property
    def artefact(self) -> bool:
        """Whether the champion's success (or part of it) is an artefact of the step."""
        return bool(self.artefacts)

    @property
    def max_change(self) -> float:
        """The largest change of a judged rate between the run's step and a check, as a fraction."""
        return max((abs(c.rate - b.rate) for check in self.checks.values()
                    for b, c in zip(self.base.rates, check.rates, strict=True) if b.verdict is not None),
                   default=0.0)

    def to_dict(self) -> dict[str, Any]:
        """The check as plain JSON types."""
        return {
            "integrators": self.integrators,
            "checks": {name: a.to_dict() for name, a in self.checks.items()},
            "max_change": self.max_change, "artefact": self.artefact, "artefacts": self.artefacts,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any], base: Assessment) -> StepCheck:
        """The check of :meth:`to_dict`, whose run's-step assessment was ``base``; a malformed
        one raises :class:`ValueError`, :class:`KeyError` or :class:`TypeError`."""
        checks = {str(name): Assessment.from_dict(a) for name, a in d["checks"].items()}
        for name, a in checks.items():
            if [r.name for r in a.rates] != [r.name for r in base.rates]:
                raise ValueError(f"the {name} check judges other rates than the run's step")
        check = cls(base=base, checks=checks, integrators=dict(d["integrators"]))
        if check.artefact != d["artefact"]:
            raise ValueError("'artefact' does not follow from the checks")
        return check


Judge = Callable[[EvolutionConfig], Assessment]
"""How a champion is judged under a config: the same network, trials and seed every call (for
example ``lambda c: dnnevo.tasks.assess(c, net, trials, seed=seed)``)."""


def step_check(judge: Judge, config: EvolutionConfig, *, base: Assessment | None = None) -> StepCheck:
    """Judges a champion with ``judge`` at the run's step (or takes ``base``, that assessment,
    already made) and at each of :func:`finer_configs`, on the same conditions."""
    if base is None:
        base = judge(config)
    finer = finer_configs(config)
    checks = {name: judge(c) for name, c in finer.items()}
    integrators = {"run": dataclasses.asdict(config.integrator),
                   **{name: dataclasses.asdict(c.integrator) for name, c in finer.items()}}
    return StepCheck(base=base, checks=checks, integrators=integrators)
