"""Tests of the pydantic -> core adapter (solver_service.adapter)."""

import math

import pytest

import shared_schema.constants as sc
from shared_schema.constants import Mechanism, SideConstants, parse_constants
from shared_schema.errors import InputError
from solver_service.core import model as core_model
from solver_service.core.model import RockingModel, RockingSide
from solver_service.workflows.adapter import models_from_file, to_rocking_model

W1 = {"id": "W1", "rocking": "two_sided", "p_eq": 2.15, "lam": 0.25, "eta": 0.90}
LOADED_SIDE = {"I0": 10000.0, "K": 40000.0, "Q": 2000.0, "phi_cr": 0.1, "M_F": 1000.0}


def test_gravity_is_the_same_on_both_sides_of_the_adapter():
    assert sc.G == core_model.G == 9.80665


def test_symmetric_published_mechanism_maps_to_symmetric_model():
    model = to_rocking_model(Mechanism.model_validate(W1))
    assert isinstance(model, RockingModel)
    assert model.positive == RockingSide(p_eq=2.15, lam=0.25, phi_ov=0.25)
    assert model.neg == model.positive
    assert model.is_symmetric
    assert model.eta == 0.9
    assert model.one_sided is False
    assert model.name == "W1"


def test_asymmetric_loaded_mechanism_keeps_side_specific_constants():
    mech = Mechanism.model_validate(
        {"id": "L1", "positive": LOADED_SIDE, "negative": LOADED_SIDE, "eta": 0.8}
    )
    model = to_rocking_model(mech)
    # theory Eqs. 4-6 and §1.8 with K phi_cr = 4000 N m, M_F = 1000 N m, g Q = 19613.3 N.
    assert model.positive.p_eq == pytest.approx(2.0, rel=1e-15)
    assert model.positive.lam == pytest.approx(3000.0 / 19613.3, rel=1e-12)
    assert model.positive.phi_ov == pytest.approx(0.075, rel=1e-12)
    assert model.neg.lam == pytest.approx(5000.0 / 19613.3, rel=1e-12)
    assert model.neg.phi_ov == pytest.approx(0.125, rel=1e-12)
    assert not model.is_symmetric


def test_one_sided_mechanism_ignores_negative_side():
    mech = Mechanism.model_validate(
        {
            "id": "F1",
            "rocking": "one_sided",
            "p_eq": 1.9,
            "lam": 0.09,
            "negative": {"p_eq": 3.0, "lam": 0.3},
            "eta": -0.6,
        }
    )
    model = to_rocking_model(mech)
    assert model.one_sided is True
    assert model.eta == -0.6
    assert model.neg == model.positive == RockingSide(1.9, 0.09, 0.09)


def test_absent_eta_stays_absent_and_time_histories_ask_for_it():
    model = to_rocking_model(Mechanism.model_validate({"id": "F1", "p_eq": 1.9, "lam": 0.09}))
    assert model.eta is None
    with pytest.raises(InputError, match=r"F1\.eta"):
        model.require_eta()


def test_models_from_file_keeps_file_order():
    cf = parse_constants([W1, dict(W1, id="W2", lam=0.2), dict(W1, id="W3", p_eq=3.0)])
    models = models_from_file(cf)
    assert [m.name for m in models] == ["W1", "W2", "W3"]
    assert [m.positive.lam for m in models] == [0.25, 0.2, 0.25]
    assert [m.positive.p_eq for m in models] == [2.15, 2.15, 3.0]


def test_rectangular_block_constants_reach_the_solver():
    b, h, density = 0.5, 3.0, 2000.0
    mass = density * b * h
    r = 0.5 * math.hypot(b, h)
    side = {
        "I0": 4.0 / 3.0 * mass * r**2,
        "K": mass * sc.G * r,
        "Q": mass * r,
        "phi_cr": math.atan(b / h),
    }
    model = to_rocking_model(Mechanism.model_validate({"id": "B", "positive": side}))
    assert model.positive.p_eq == pytest.approx(math.sqrt(3 * sc.G / (4 * r)), rel=1e-12)
    assert model.positive.lam == pytest.approx(math.atan(b / h), rel=1e-12)


def test_unvalidated_mechanism_is_rejected_naming_the_missing_field():
    mech = Mechanism.model_construct(
        id="X", rocking="two_sided", positive=SideConstants.model_construct(p_eq=2.0, lam=0.2)
    )
    with pytest.raises(InputError) as info:
        to_rocking_model(mech)
    assert info.value.field == "X.positive.phi_ov"
