"""A place south of the equator or west of Greenwich given after a space (``--home -35.3632,149.1652,584``, as the
docs write it) is the option's value: argparse read it as an unknown option and refused the line."""

from __future__ import annotations

import pytest
from aeroexec.cli.main import build_parser, main


def test_a_southern_home_after_a_space_is_read(capsys):
    assert main(["verify", "missions/figure10.xml", "--home", "-35.3632,149.1652,584"]) == 0
    assert "0 errors, 0 warnings; ready to fly" in capsys.readouterr().out
    for command in ("run", "verify", "convert", "sim"):
        argv = [command, *(["missions/figure10.xml"] if command != "sim" else []), "--home", "-35.3632,-49.1652"]
        assert build_parser(argv).parse_args(argv).home is not None


def test_a_misspelt_option_before_a_southern_place_is_still_refused(capsys):
    with pytest.raises(SystemExit) as exit:
        main(["verify", "missions/figure10.xml", "--hmoe", "-35.3632,149.1652"])
    assert exit.value.code == 2
    assert "unrecognized arguments: --hmoe -35.3632,149.1652 (did you mean --home?)" in capsys.readouterr().err
