"""The Examples sections of the geometry modules run and are true."""

import doctest
import importlib

import pytest

MODULES = ["massprops", "validate", "cut", "contact", "frames", "polygon", "topology"]


@pytest.mark.parametrize("name", MODULES)
def test_module_examples(name):
    module = importlib.import_module(f"cad_maths.geometry.{name}")
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert result.failed == 0
    assert result.attempted > 0
