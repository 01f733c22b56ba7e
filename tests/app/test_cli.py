import subprocess
import sys

from partlab.cli import COMMANDS, build_parser, main


def test_every_contract_command_is_there():
    assert list(COMMANDS) == ["track", "batch", "train", "eval", "export", "import", "synth", "calibrate", "app",
                             "users", "serve-ml"]
    parser = build_parser()
    args = parser.parse_args(["track", "v.mp4", "-o", "t.csv", "--tracker", "limbs", "--seed", "3"])
    assert (args.video, args.output, args.tracker, args.seed) == ("v.mp4", "t.csv", "limbs", 3)


def test_console_script_help():
    out = subprocess.run([sys.executable, "-m", "partlab.cli", "--help"], capture_output=True, text=True)
    assert out.returncode == 0
    for name in COMMANDS:
        assert name in out.stdout


def test_no_command_prints_help(capsys):
    assert main([]) == 2
    assert "COMMAND" in capsys.readouterr().out
