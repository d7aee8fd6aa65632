"""`python -m ddg warmup` compiles every model's kernels: a model it leaves out compiles them in the
user's first run instead (the cross-section ribbon's took 80 s and 2.2 GB of memory, measured)."""
import inspect
import subprocess
import sys

from ddg import api, warmup


def test_the_warmup_has_a_part_for_every_model_the_api_offers():
    assert set(api.DEFAULT_RESOLUTION) <= set(warmup.PARTS)
    source = inspect.getsource(warmup)
    for name in api.DEFAULT_RESOLUTION:
        cls = api._model_class(name)
        assert f"{cls.__name__}(" in source, f"{name} ({cls.__name__}) is not warmed up"


def test_an_unknown_part_or_job_count_is_refused_in_one_line():
    for argv in (["warmup", "spaghetti"], ["warmup", "--jobs", "0"]):
        done = subprocess.run([sys.executable, "-m", "ddg", *argv], capture_output=True, text=True, timeout=60)
        assert done.returncode == 2
        assert len(done.stderr.strip().splitlines()) == 1, done.stderr
