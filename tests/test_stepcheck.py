"""dnnevo.evaluation.stepcheck: which champions the time-step check calls step artefacts, on hand-made
assessments, and the finer integrations it compares with."""

from __future__ import annotations

import doctest

import pytest

from dnnevo import tasks
from dnnevo.evaluation import assessment as assess
from dnnevo.evaluation import stepcheck
from dnnevo.config import EvolutionConfig, IntegratorConfig
from dnnevo.errors import ConfigError


def test_doctests() -> None:
    assert doctest.testmod(stepcheck).failed == 0


def assessment(*rights: int, n: int = 200) -> assess.Assessment:
    rates = [assess.rate(f"{i}*", k, n, threshold=0.9) for i, k in enumerate(rights)]
    return assess.Assessment(task="sequence", trials=n, unit="trials per target", seed=1, rates=rates,
                             verdict=assess.combine([r.verdict or "fail" for r in rates]), method="m")


def check(base: assess.Assessment, **checks: assess.Assessment) -> stepcheck.StepCheck:
    return stepcheck.StepCheck(base=base, checks=checks, integrators={})


def test_an_artefact_is_a_rate_that_fails_only_at_a_finer_step() -> None:
    # 200/200 passes, 182/200 (91%) is undecided, 150/200 fails against 90%.
    robust = check(assessment(200, 200), fine=assessment(199, 200), rk4=assessment(200, 198))
    assert not robust.artefact and robust.max_change == pytest.approx(0.01)
    lost = check(assessment(200, 182), fine=assessment(200, 150), rk4=assessment(200, 182))
    assert lost.artefacts == ["fine: 1*"] and lost.max_change == pytest.approx(0.16)
    both = check(assessment(200, 200), fine=assessment(4, 200), rk4=assessment(10, 200))
    assert both.artefacts == ["fine: 0*", "rk4: 0*"]
    # Failing at the run's step already is a failure, not an artefact; nor is a drop to undecided.
    assert not check(assessment(150, 200), fine=assessment(4, 200)).artefact
    assert not check(assessment(200, 200), fine=assessment(182, 200)).artefact
    assert lost.to_dict()["artefacts"] == ["fine: 1*"]


def test_the_finer_integrations_keep_each_time_step_as_long() -> None:
    euler = EvolutionConfig()
    finer = stepcheck.finer_configs(euler)
    assert finer["dt/10"].integrator == IntegratorConfig(method="euler", dt=0.01, substeps=100)
    assert finer["rk4"].integrator == IntegratorConfig(method="rk4", dt=0.1, substeps=10)
    rk4 = EvolutionConfig(integrator=IntegratorConfig(method="rk4", dt=0.05, substeps=20))
    assert list(stepcheck.finer_configs(rk4)) == ["dt/10"]
    assert stepcheck.finer_configs(rk4)["dt/10"].integrator == IntegratorConfig("rk4", 0.005, 200)


@pytest.mark.parametrize("dt", [0.03, 0.0, -1.0, float("nan"), float("inf"), 1.5])
def test_a_step_that_does_not_divide_the_time_step_is_an_error(dt: float) -> None:
    with pytest.raises(ConfigError, match="dt"):
        stepcheck.with_dt(EvolutionConfig(), dt)


def test_a_champion_that_depends_on_the_step_is_flagged() -> None:
    # The final champion of `dnnevo sweep landmark --seeds 0-9 --set elitism=5 --set
    # generations=200`, seed 2: right in 95-97.5% of ideal trials at the Euler step of 0.1, and
    # in at most 10% when integrated 10x finer or with RK4.
    from pathlib import Path

    from dnnevo import _core
    from dnnevo import presets

    net = _core.Network.load(Path(__file__).parent / "data" / "landmark-step-artefact.json")
    config = presets.get("landmark")
    check = stepcheck.step_check(lambda c: tasks.assess(c, net, 20, seed=2), config)
    assert check.base.verdict != "fail" and check.base.judged[0].rate >= 0.95
    assert check.artefacts == ["dt/10: overall", "rk4: overall"]
    assert all(a.judged[0].rate <= 0.1 for a in check.checks.values())
    assert check.max_change >= 0.85


def test_the_report_marks_every_failing_rate_and_says_what_the_mark_means() -> None:
    from dnnevo.cli.assess import step_lines

    integrators = {"run": {"method": "euler", "dt": 0.1}, "dt/10": {"method": "euler", "dt": 0.01},
                   "rk4": {"method": "rk4", "dt": 0.1}}
    failing = stepcheck.StepCheck(base=assessment(200, 0), checks={"dt/10": assessment(200, 0),
                                                                   "rk4": assessment(200, 0)},
                                  integrators=integrators)
    lines = step_lines(failing)
    # A rate failing at the run's step is marked there too, and the mark is explained although
    # there is no artefact.
    assert lines[-2].split() == ["1*", "0.0%!", "0.0%!", "0.0%!"], lines
    assert lines[-1] == "step check: no artefact (largest change 0.0 points) (! marks a failing rate)"
    passing = stepcheck.StepCheck(base=assessment(200, 200), checks={"dt/10": assessment(200, 200),
                                                                     "rk4": assessment(200, 200)},
                                  integrators=integrators)
    assert "!" not in "".join(step_lines(passing))
