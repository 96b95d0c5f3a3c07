"""Specs, diagnostics and spec errors pickle, so they cross process boundaries."""

from __future__ import annotations

import multiprocessing
import pickle

import numpy as np
import pytest

import hstl
from conftest import CLI_FIXTURES

TRACE = {"x": [0, 5, 5, 3, 10, 12], "y": [0, 12, 12, 3, 3, 4]}


def test_a_loaded_spec_round_trips_by_its_source():
    spec = hstl.Spec.load(CLI_FIXTURES / "surveillance.hstl")
    back = pickle.loads(pickle.dumps(spec))
    assert back == spec and hash(back) == hash(spec)
    assert (back.name, back.filename, back.source) == (spec.name, spec.filename, spec.source)
    assert np.array_equal(back.signal(TRACE, "A"), spec.signal(TRACE, "A"))


def test_a_spec_picked_by_name_round_trips_with_its_name():
    text = (CLI_FIXTURES / "two_specs.hstl").read_text()
    spec = hstl.Spec.parse(text, filename="two.hstl", name="Second")
    for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
        back = pickle.loads(pickle.dumps(spec, protocol))
        assert back.name == "Second" and back.filename == "two.hstl" and back == spec


def test_spec_errors_and_diagnostics_round_trip():
    with pytest.raises(hstl.SpecError) as e:
        hstl.Spec.load(CLI_FIXTURES / "errors.hstl")
    back = pickle.loads(pickle.dumps(e.value))
    assert type(back) is hstl.SpecError and str(back) == str(e.value)
    assert back.diagnostics == e.value.diagnostics and len(back.diagnostics) >= 3
    d = e.value.diagnostics[0]
    assert pickle.loads(pickle.dumps(d)) == d
    with pytest.raises(hstl.MissingVariableError) as missing:
        hstl.Spec.load(CLI_FIXTURES / "surveillance.hstl").signal({"x": [1]})
    assert str(pickle.loads(pickle.dumps(missing.value))) == str(missing.value)


def score(spec):
    return spec.signal(TRACE).tolist()


def test_a_spec_crosses_to_a_spawned_process():
    spec = hstl.Spec.load(CLI_FIXTURES / "surveillance.hstl")
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        assert pool.map(score, [spec]) == [score(spec)]


def test_worlds_and_policies_round_trip_by_their_contents():
    from conftest import REPO

    world = hstl.World.load(REPO / "examples" / "worlds" / "warehouse.toml")
    policy = hstl.train(CLI_FIXTURES / "small.hstl", seed=4, episodes=2)
    for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
        assert pickle.loads(pickle.dumps(world, protocol)) == world
        back = pickle.loads(pickle.dumps(policy, protocol))
        assert back == policy and back.json == policy.json
        assert back.curve.tolist() == policy.curve.tolist() and back.steps == policy.steps
        assert back.q_tables["options"].tobytes() == policy.q_tables["options"].tobytes()


def window_rate(policy):
    return policy.evaluate(starts=2, steps=300, optimum=False)["window_rate"]


def test_a_policy_crosses_to_a_spawned_process():
    policy = hstl.train(CLI_FIXTURES / "small.hstl", seed=4, episodes=2)
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        assert pool.map(window_rate, [policy]) == [window_rate(policy)]
