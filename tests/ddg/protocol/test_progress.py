"""Progress on stderr (issue 18 item 5): on a terminal a bar rewritten in place with an ETA; in a log
or notebook (not a terminal) plain lines at each tenth of the path; the steps after the path
(thresholds, branches) announced with their time; nothing when not asked."""
import io

from ddg.cli import main
from ddg.protocol.progress import ProgressBar


class Terminal(io.StringIO):
    def isatty(self):
        return True


ROW = {"dL_over_L": 0.5, "dW_over_L": 0.1, "phase": "U"}


def test_plain_lines_at_each_tenth_when_not_a_terminal():
    stream = io.StringIO()
    bar = ProgressBar(40, True, stream)
    for _ in range(40):
        bar("shear", None, ROW)
    bar.announce("threshold location")
    bar.announce("threshold location", done=True)
    bar.close()
    lines = stream.getvalue().splitlines()
    path = [line for line in lines if line.startswith("progress: path")]
    assert len(path) == 10 and "\r" not in stream.getvalue()
    assert path[0].startswith("progress: path  10% (4/40 steps)") and "ETA" in path[0]
    assert path[-1].startswith("progress: path 100% (40/40 steps)") and "ETA" not in path[-1]
    assert lines[-2:] == ["progress: threshold location...", "progress: threshold location done in 0 s"]


def test_a_bar_with_an_eta_on_a_terminal():
    stream = Terminal()
    bar = ProgressBar(4, True, stream)
    bar("compression", None, ROW)
    bar.announce("branch tracing")
    text = stream.getvalue()
    assert text.startswith("\r[#######") and "25.0%" in text and "ETA" in text
    assert "\nprogress: branch tracing...\n" in text          # the bar's line is ended first


def test_silent_unless_asked(capsys):
    stream = io.StringIO()
    bar = ProgressBar(4, False, stream)
    bar("shear", None, ROW)
    bar.announce("x")
    bar.close()
    assert stream.getvalue() == ""


def test_the_command_line_reports_progress_in_a_log(tmp_path, capsys):
    args = ["simulate", "--model", "rod", "--resolution", "20", "--shear-ratio", "0.4", "--compression-steps", "5",
            "--shear-steps", "5", "--out", str(tmp_path)]
    assert main(args) == 0
    err = capsys.readouterr().err
    assert "progress: path 100% (11/11 steps)" in err
    assert "progress: threshold location..." in err and "progress: threshold location done in" in err
    assert main(args + ["--quiet"]) == 0 and "progress" not in capsys.readouterr().err
