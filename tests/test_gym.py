"""dnnevo.closedloop.gym: Gymnasium's vector environments as closed-loop tasks, in every autoreset
mode, with common random numbers where the environment allows them. That CartPole-v1 is solved
is checked by docs/closed-loop.md's example, which tests/test_docs.py runs."""

from __future__ import annotations

import numpy as np
import pytest

import dnnevo
from dnnevo import ConfigError
from dnnevo.closedloop import rollout
from dnnevo.closedloop.gym import GymEnvironment


def networks(count: int, n: int = 4, m: int = 4, seed: int = 0) -> list[dnnevo.Network]:
    return [dnnevo.Network.random(n, m, seed=seed + k) for k in range(count)]


@pytest.mark.parametrize("mode", ["next_step", "same_step", "disabled"])
def test_every_autoreset_mode_gives_the_same_episodes(mode: str) -> None:
    """Each row runs one episode and leaves when it ends, so what the vector environment does
    after an end is never read; with autoreset disabled the ended sub-environments are reset so
    that stepping them is allowed."""
    nets = networks(6)
    reference = rollout(nets, GymEnvironment("CartPole-v1", actions="threshold", vectorization_mode="sync"),
                        episodes=3, max_steps=200, seed=5)
    env = GymEnvironment("CartPole-v1", actions="threshold", vectorization_mode="sync",
                         autoreset_mode=mode)
    result = rollout(nets, env, episodes=3, max_steps=200, seed=5)
    assert env.envs.metadata["autoreset_mode"].name.lower() == mode
    assert np.array_equal(result.returns, reference.returns)
    assert np.array_equal(result.lengths, reference.lengths)
    assert result.lengths.min() < 200 and result.lengths.max() > result.lengths.min()


def test_separate_environments_give_every_network_the_same_starts() -> None:
    same = networks(1) * 4
    sync = rollout(same, GymEnvironment("CartPole-v1", actions="threshold", vectorization_mode="sync"),
                   episodes=3, max_steps=100, seed=1)
    assert np.all(sync.returns == sync.returns[0])
    # A natively vectorised environment takes one seed for all its rows: no common starts.
    native = rollout(same, GymEnvironment("CartPole-v1", actions="threshold"), episodes=3,
                     max_steps=100, seed=1)
    assert not np.all(native.returns == native.returns[0])


def test_actions_from_rates() -> None:
    rates = np.array([[0.2, 0.9, 0.1], [0.7, 0.3, 0.8]])
    argmax = GymEnvironment("CartPole-v1", actions="argmax")
    assert argmax._act(rates).tolist() == [1, 0]
    chosen = GymEnvironment("CartPole-v1", actions="argmax", outputs=[2, 0])
    assert chosen._act(rates).tolist() == [1, 0]
    threshold = GymEnvironment("CartPole-v1", actions="threshold", outputs=[2])
    assert threshold._act(rates).tolist() == [0, 1]
    box = GymEnvironment("Pendulum-v1", actions="box", vectorization_mode="sync")  # one torque in [-2, 2]
    assert box._act(rates).reshape(-1).tolist() == pytest.approx([-1.2, 0.8])


def test_observations_kept_and_scaled() -> None:
    env = GymEnvironment("CartPole-v1", observations=[0, 2], observation_scale=[1.0, 5.0])
    assert env.observation_size == 2
    obs = env._observe(np.array([[1.0, 2.0, 3.0, 4.0]], dtype=np.float32))
    assert obs.tolist() == [[1.0, 15.0]]


@pytest.mark.parametrize("kwargs, message", [
    ({"actions": "softmax"}, "actions is 'softmax'"),
    ({"actions": "box"}, "needs a Box action space"),
    ({"outputs": [0]}, "outputs names 1 neuron;"),
    ({"outputs": [-1, 0]}, r"outputs is \[-1, 0\]; expected neuron numbers >= 0"),
    ({"observation_scale": [1.0, 2.0]}, "observation_scale is .*one per kept observation"),
    ({"observation_scale": float("nan")}, "every scale must be finite"),
    ({"make_kwargs": {"gravity": 3}}, r"gymnasium.make\('CartPole-v1', \*\*make_kwargs\) failed: TypeError"),
    ({"observations": [4]}, "CartPole-v1 has 4 components"),
    ({"observations": [True, False, True, False]}, "expected a list of component numbers"),
    ({"observations": [[0, 2]]}, "expected a list of component numbers"),
    ({"vectorization_mode": "Sync"}, "vectorization_mode is 'Sync'; expected one of"),
    ({"autoreset_mode": "sometimes"}, "autoreset_mode is 'sometimes'"),
])
def test_bad_settings_are_config_errors(kwargs: dict, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        GymEnvironment("CartPole-v1", **kwargs)


@pytest.mark.parametrize("mode", ["next_step", "same_step", "disabled"])
def test_fewer_rows_than_episodes_give_the_same_episodes_in_separate_environments(mode: str) -> None:
    """restart resets a separate sub-environment with its episode number's seed, whatever the
    autoreset mode, so queued episodes are the episodes of a rollout that runs them all at once."""
    nets = networks(6)
    everything = rollout(nets, GymEnvironment("CartPole-v1", actions="threshold", vectorization_mode="sync"),
                         episodes=3, max_steps=200, seed=5)
    env = GymEnvironment("CartPole-v1", actions="threshold", vectorization_mode="sync",
                         autoreset_mode=mode)
    queued = rollout(nets, env, episodes=3, max_steps=200, seed=5, rows=4)
    assert env.envs.num_envs == 4
    assert np.array_equal(queued.returns, everything.returns)
    assert np.array_equal(queued.lengths, everything.lengths)


def test_a_native_vector_environment_starts_queued_episodes_at_its_next_step() -> None:
    """CartPoleVectorEnv resets an ended sub-environment at its next step (next-step autoreset):
    the row waits out that step, and its new episode begins from a fresh start, so a copied
    network's episodes are as long as they are when every episode runs at once (within the
    spread of starting states), and every episode is counted once."""
    controller = networks(1)
    nets = controller * 10
    everything = rollout(nets, GymEnvironment("CartPole-v1", actions="threshold"), episodes=2,
                         max_steps=500, seed=3)
    queued = rollout(nets, GymEnvironment("CartPole-v1", actions="threshold"), episodes=2,
                     max_steps=500, seed=3, rows=4)
    assert queued.lengths.shape == (10, 2) and queued.lengths.min() >= 1
    assert np.array_equal(queued.returns, queued.lengths.astype(float))  # reward 1 per step
    lo, hi = np.percentile(everything.lengths, [0, 100])
    assert lo - 5 <= np.median(queued.lengths) <= hi + 5


class _Words:
    """A stand-in environment whose observations are text: a space without a shape."""

    def __init__(self) -> None:
        import gymnasium as gym

        self.observation_space = gym.spaces.Text(5)
        self.action_space = gym.spaces.Discrete(2)
        self.metadata: dict = {}

    def close(self) -> None:
        pass


def test_an_observation_space_without_a_shape_is_named_in_one_line(monkeypatch: pytest.MonkeyPatch) -> None:
    import gymnasium as gym

    monkeypatch.setattr(gym, "make", lambda env_id, **kwargs: _Words())
    with pytest.raises(ConfigError, match="Words-v0's observation space has no shape"):
        GymEnvironment("Words-v0")


class _Acting:
    """A stand-in environment with a given action space."""

    def __init__(self, space) -> None:
        import gymnasium as gym

        self.observation_space = gym.spaces.Box(-1.0, 1.0, (2,))
        self.action_space = space
        self.metadata: dict = {}

    def close(self) -> None:
        pass


def test_actions_keep_to_the_space_and_a_space_they_cannot_fill_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    """Discrete's start, Box's dtype; Box bounds that are not finite cannot be scaled onto."""
    import gymnasium as gym
    from gymnasium.spaces import Box, Discrete

    space: list = []
    monkeypatch.setattr(gym, "make", lambda env_id, **kwargs: _Acting(space[0]))
    rates = np.array([[0.2, 0.9, 0.1], [0.7, 0.3, 0.8]])
    for given, actions, want in [
        (Discrete(3, start=-1), "argmax", [0, 1]),
        (Discrete(2, start=5), "threshold", [5, 6]),
        (Box(-2.0, 2.0, (1,), dtype=np.float32), "box", [-1.2, 0.8]),
        (Box(0, 10, (1,), dtype=np.int64), "box", [2, 7]),
    ]:
        space[:] = [given]
        env = GymEnvironment("Acting-v0", actions=actions, outputs=[2] if actions == "threshold" else None)
        acted = env._act(rates)
        assert acted.reshape(-1).tolist() == pytest.approx(want), given
        assert all(given.contains(a.astype(given.dtype)) for a in acted) and acted.dtype.kind == given.dtype.kind
    for given in (Box(-np.inf, np.inf, (1,)), Box(0.0, np.inf, (1,))):
        space[:] = [given]
        with pytest.raises(ConfigError, match="must be finite; Acting-v0 has Box"):
            GymEnvironment("Acting-v0", actions="box")


def test_an_environment_without_a_native_vector_form_is_told_to_use_sync() -> None:
    with pytest.raises(ConfigError, match='Pendulum-v1 has no native vector environment.*vectorization_mode="sync"'):
        GymEnvironment("Pendulum-v1", actions="box")
    assert GymEnvironment("Pendulum-v1", actions="box", vectorization_mode="sync").observation_size == 3
    with pytest.raises(ConfigError, match="Pendulum has no native vector environment"):
        GymEnvironment("Pendulum", actions="box")  # the latest version, as gymnasium.make takes it


def test_an_unknown_environment_is_a_config_error() -> None:
    with pytest.raises(ConfigError, match=r"gymnasium.make\('CartPol-v1', \*\*make_kwargs\) failed: NameNotFound"):
        GymEnvironment("CartPol-v1")


def test_the_command_line_runs_a_gymnasium_environment_by_its_class(tmp_path) -> None:
    """GymEnvironment counts its observations per instance; the command line takes it so."""
    from cli_helpers import run_cli

    r = run_cli("run", "python:dnnevo.closedloop.gym.GymEnvironment", "--set", "task_params.env_id=CartPole-v1",
                "--set", "task_params.max_steps=20", "--set", "task_params.episodes=2", "--set", "size=3",
                "--set", "selection=rank", "--quick", "--threads", "1", "--out", tmp_path / "run")
    assert r.returncode == 0, r.stderr
    assert "n_inputs = 4" in (tmp_path / "run" / "config.toml").read_text()
    drawn = run_cli("plot", tmp_path / "run")
    assert drawn.returncode == 0, drawn.stderr
