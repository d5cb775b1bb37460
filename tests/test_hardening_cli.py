"""Bad command-line arguments: one line ``wheelrail: error: ...`` naming the option and the value, exit status 2."""

import pytest
from hardening_helpers import assert_error, run


@pytest.mark.parametrize(
    ("argv", "fragments"),
    [
        (["fly"], ["argument COMMAND: invalid choice: 'fly'"]),
        (["run", "--speed", "3"], ["unrecognized arguments: --speed"]),
        (["contact"], ["contact: the following arguments are required: case"]),
        (["contact", "hertz-quadric", "--method", "kalker"], ["--method 'kalker'"]),
        (["contact", "no-such-case"], ["case 'no-such-case'", "no such file"]),
        (["contact", "missing.toml"], ["case file 'missing.toml': no such file"]),
        (["run", "no-such-scene"], ["scene 'no-such-scene'"]),
        (["conicity", "--gauge-m", "abc"], ["--gauge-m", "'abc': expected a finite number"]),
        (["conicity", "--amplitude-m", "nan"], ["--amplitude-m", "'nan'"]),
        (["conicity", "--amplitude-m", "-0.003"], ["--amplitude-m -0.003", "> 0"]),
        (["conicity", "--wheel", "no-such-profile"], ["--wheel 'no-such-profile'"]),
        (["conicity", "--gauge-m", "1e30"], ["--gauge-m 1e+30", "from 0.1 to 3"]),  # was a ZeroDivisionError
        (["conicity", "--rail-inclination-rad", "3"], ["--rail-inclination-rad 3.0", "-0.2 to 0.2"]),
        (["stress", "--workers", "0"], ["--workers '0': expected an integer >= 1"]),
        (["stress", "--workers", "two"], ["--workers 'two'"]),
        (["manchester", "--method", "kalker"], ["--method 'kalker'"]),
        (["run", "--out", ""], ["--out", "'': expected a folder path"]),
        (["demo", "--patch-geometry", "round"], ["--patch-geometry: invalid choice: 'round'", "'sampled', 'ellipse'"]),
    ],
)
def test_bad_arguments(capsys, tmp_path, monkeypatch, argv, fragments):
    monkeypatch.chdir(tmp_path)
    code, out, err = run(capsys, *argv)
    assert_error(code, err, *fragments)
    assert list(tmp_path.iterdir()) == []  # nothing written anywhere


def test_help_and_version_exit_zero(capsys):
    with pytest.raises(SystemExit) as info:
        run(capsys, "--version")
    assert info.value.code == 0
