"""Import paths of 0.1 keep working for one release, with a DeprecationWarning naming the new place."""

import importlib
import sys

import pytest

from aeroexec._moved import MOVED


@pytest.mark.parametrize("old", sorted(MOVED))
def test_an_old_path_forwards_to_the_new_module_with_a_warning(old):
    sys.modules.pop(old, None)
    with pytest.warns(DeprecationWarning, match=MOVED[old].replace(".", r"\.")):
        module = importlib.import_module(old)
    new = importlib.import_module(MOVED[old])
    public = [n for n in vars(new) if not n.startswith("_")]
    assert public and all(getattr(module, n) is getattr(new, n) for n in public)


def test_the_readme_specialist_import_of_0_1_still_works():
    sys.modules.pop("aeroexec.engine.specialist", None)
    with pytest.warns(DeprecationWarning):
        from aeroexec.engine.specialist import BehaviorSpecialist
    assert BehaviorSpecialist().check_sequence(["TAKE_OFF", "LAND", "LAND"])
