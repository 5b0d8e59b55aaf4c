"""A lab's own experiment from Python: the description as a dict, read by
the same types as an experiment file (its errors name the same fields);
keyword mistakes are TypeErrors raised before palpate runs."""

from __future__ import annotations

import numpy as np
import pytest

import palpate

GEL = {
    "specimen": {"shape": "cylinder", "radius": 20.0, "height": 10.0, "support": "bonded"},
    "materials": {"gel": {"law": "neo-hookean", "C10": {"start": 2e-3}}},
    "tool": {"shape": "sphere", "radius": 2.5},
    "protocol": {"segments": [{"ramp_to": 0.5}], "samples": 5},
}


def test_a_keyword_mistake_is_a_type_error():
    with pytest.raises(TypeError, match="experiment"):
        palpate.simulate()
    with pytest.raises(TypeError, match="experiment"):
        palpate.simulate("N1", experiment=GEL)
    with pytest.raises(TypeError, match="experiment"):
        palpate.calibrate(experiment=3.0, data=(np.zeros(3), np.zeros(3)))
    with pytest.raises(TypeError, match="data"):
        palpate.calibrate(experiment=GEL)
    with pytest.raises(TypeError, match="mesh_level"):
        palpate.simulate(experiment=GEL, mesh_level=2)


def test_a_bad_field_of_the_dict_is_named():
    bad = {**GEL, "materials": {"gel": {"law": "neo-hookean", "C01": {"start": 2e-3}}}}
    with pytest.raises(palpate.PalpateError, match="materials.gel.C01"):
        palpate.simulate(experiment=bad)
    bad = {**GEL, "specimen": {**GEL["specimen"], "raduis": 20.0}}
    with pytest.raises(palpate.PalpateError, match="raduis"):
        palpate.simulate(experiment=bad)


def test_an_option_the_description_holds_is_refused():
    with pytest.raises(palpate.PalpateError, match="--mesh"):
        palpate.simulate(experiment=GEL, mesh="fine")
