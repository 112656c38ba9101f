"""What a command imports before it does anything (issue 45): each module a start-up does not need is CPU every
``aeroexec`` command pays, measured by ``bench/startup.py`` against the interpreter's own start."""

from __future__ import annotations

import subprocess
import sys
import textwrap


def imported_after(code: str) -> set[str]:
    """The modules a fresh interpreter holds after running ``code``."""
    script = textwrap.dedent(code) + "\nimport sys\nprint('\\n'.join(sorted(sys.modules)))\n"
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True, cwd="/")
    return set(done.stdout.split())


def test_a_plugin_group_no_package_names_is_answered_without_reading_every_package():
    modules = imported_after("""
        from aeroexec.plugins import installed_plugins
        assert installed_plugins("aeroexec.no-such-group") == []
    """)
    assert "importlib.metadata" not in modules


def test_a_plugin_group_a_package_names_is_still_read(tmp_path):
    site = tmp_path / "site"
    (site / "toy_group-0.1.dist-info").mkdir(parents=True)
    (site / "toy_group-0.1.dist-info" / "METADATA").write_text("Metadata-Version: 2.1\nName: toy-group\n"
                                                                 "Version: 0.1\n")
    (site / "toy_group-0.1.dist-info" / "entry_points.txt").write_text("[aeroexec.toy_group]\nanswer = json:dumps\n")
    modules = imported_after(f"""
        import sys
        sys.path.insert(0, {str(site)!r})
        import json
        from aeroexec.plugins import installed_plugins
        assert installed_plugins("aeroexec.toy_group", named=True) == [("answer", json.dumps)]
    """)
    assert "importlib.metadata" in modules
