"""``hrgtc simulate --logger``: each preset and each logger option, with a fixed seed, writes
the same bytes as before the options were generated from ``LoggerSettings`` (issue 22).

The expected SHA-256 digests were recorded on the commit before the change (f7023af), where
the options were declared by hand in ``cli/simulate_cmd.py``: the CSV the logger writes, the
sidecar ``.truth.json`` (the logger's settings, spikes, orientations, ...), the per-row
``.truth.csv`` and the hand log. A digest that changes means the simulator writes something
else for the same command line.
"""

from __future__ import annotations

import hashlib
import json

import pytest
from typer.testing import CliRunner

from hrgtc.cli import app

#: Command lines (after ``hrgtc simulate``): every preset, and every logger option given.
CASES = {
    "pan-cold": ["--logger", "pan-cold"],
    "fridge-3day": ["--logger", "fridge-3day"],
    "fridge-3day-short": ["--logger", "fridge-3day", "--hours", "6", "--profile", "constant",
                          "--temperature", "20"],
    "burst-docs": ["--logger", "burst", "--unit", "mems-3", "--profile", "cooldown", "--start",
                   "22", "--end", "5", "--hours", "2", "--ramp-rate", "0.15", "--rate-hz", "50",
                   "--burst-s", "5", "--period-s", "300", "--time-unit", "ms", "--rate-unit",
                   "radps", "--rate-digits", "3", "--spikes", "3"],
    "continuous-hrg": ["--logger", "continuous", "--profile", "constant", "--hours", "0.2",
                       "--rate-hz", "10"],
    "burst-hrg": ["--logger", "burst", "--profile", "cooldown", "--hours", "1",
                  "--rate-hz", "20"],
    "continuous-mems": ["--logger", "continuous", "--unit", "mems-3", "--profile", "constant",
                        "--hours", "0.2", "--rate-hz", "10"],
    "every-option-imu3": [
        "--logger", "continuous", "--unit", "imu-3", "--profile", "cooldown", "--end", "0",
        "--hours", "0.5", "--rate-hz", "10", "--time-unit", "us", "--counter-bits", "32",
        "--clock-start-s", "4290", "--jitter-ms", "0.3", "--restarts", "600,1200",
        "--run-offset-dph", "2", "--warmup-dph", "5", "--warmup-tau-s", "60", "--rate-unit",
        "dps", "--rate-digits", "5", "--temp-lsb", "0.01", "--temp-offset", "20",
        "--temp-bits", "16", "--temp-rate-hz", "1", "--reference-log", "--reference-lag-s",
        "60", "--duplicates", "3", "--spikes", "2", "--spike-dph", "500", "--orientations",
        "2", "--handling-max-dps", "200", "--hand-warming-c", "1", "--accelerometer"],
    "every-option-mems-burst": [
        "--logger", "burst", "--unit", "mems-3", "--profile", "warmup", "--start", "10",
        "--hours", "0.3", "--rate-hz", "25", "--burst-s", "10", "--period-s", "120",
        "--time-unit", "ms", "--temp-lsb", "0.05", "--temp-rate-hz", "0.5", "--reference-log",
        "--orientations", "3", "--hand-warming-c", "2", "--spikes", "4"],
    "timestamp": ["--logger", "continuous", "--profile", "constant", "--hours", "2",
                  "--rate-hz", "0.5", "--time-unit", "timestamp", "--wall-start",
                  "2021-03-28T00:30:00", "--tz", "Europe/Berlin"],
    "pan-cold-overrides": ["--logger", "pan-cold", "--spikes", "0", "--no-reference-log",
                           "--hours", "0.5", "--profile", "constant", "--rate-unit", "dph",
                           "--temp-offset", "20", "--jitter-ms", "0", "--period-s", "100"],
    "pan-cold-lag": ["--logger", "pan-cold", "--reference-lag-s", "60", "--temp-bits", "20",
                     "--sample-rate-hz", "10", "--accelerometer", "--orientations", "2"],
    "fridge-overrides": ["--logger", "fridge-3day", "--profile", "constant", "--hours", "3",
                         "--orientations", "2", "--handling-max-dps", "100",
                         "--temp-lsb", "0.1", "--restarts", "5000"],
}

#: SHA-256 of each file written (name -> digest), recorded on f7023af.
EXPECTED: dict[str, dict[str, str]] = {
    "burst-docs": {
        "run.csv": "4d3beea14a7802bea80952edcc7547230ae1d28221e9b279b2249e02b6dc236e",
        "run.truth.csv": "44d5b49e241a3b5730147eda05bda9c56d103e3d9108e5b1ae46e5ddf3c2545a",
        "run.truth.json": "a4de222cb4a3fabc6c7454e5c45555bdc7235badf62b3f3eb935652a51ae24c1",
    },
    "burst-hrg": {
        "run.csv": "75f9371b9c3cbf452423b7f81d9f1ea6e8f3d76f83f22f71694cf48616a95d7f",
        "run.truth.csv": "bc4fdee38c7419ca06872c3dcefb2b40e28759a75a8a8287bfe139683d514372",
        "run.truth.json": "c357f02f400eb4edd0f238e71d0cb701d6ba96b440558a351333e4d97e165c0e",
    },
    "continuous-hrg": {
        "run.csv": "49460f27c92046b4b7dffea03b28a1b71615ab66a6ac6c871778607b2e7a8e35",
        "run.truth.csv": "9943fc3f27a6ba6a57bbc90b06a6f986b11f6f005f39cd426921caccc5951c3e",
        "run.truth.json": "f1c06657619959da987aab43c38e4a31c619178eb4a18ab6932c3065030f5ab7",
    },
    "continuous-mems": {
        "run.csv": "9c1947f8d7ab044ccc8187f5664c1c462067d1d502f62a317d8af412216e241e",
        "run.truth.csv": "ec69e9f0346936ca59fa0788833822362dfa3ab94c432ac4b9b67c83dec2fdbf",
        "run.truth.json": "e180d54592c18519fb733f600b05554dc6d341a13120acd1e6ae50767cd13ae7",
    },
    "every-option-imu3": {
        "run.csv": "db3c2912cb289e743385123eff9711d7dd3a4c7c5d00a6ed980d82b230a5382c",
        "run.truth.csv": "ae32792432a79a4f43e6e1c13355d0ef8798d37e7f74ab1f045802e77162c16d",
        "run.truth.json": "a09212002552d65eb60cd393d11ddfbade17717b09a979322247545ccf21b15d",
        "run_reflog.csv": "1427e163b38536e1d53d1faa3a5cacdf9a2036af499bfffa78fda84e79bc8c9f",
    },
    "every-option-mems-burst": {
        "run.csv": "2792981592c45ebbd29fb757fcd6637f0b94fea1c59970188f52d219e20e1005",
        "run.truth.csv": "414acc4c3e583fbc01019e39a0678e1479ed0d12bcf5cbb6eafa860659432b94",
        "run.truth.json": "2ec0f304128fcb1ec1f80701a91c6c405d4c137631849d3b9e261c7b85ab1dff",
        "run_reflog.csv": "c2e1881ddeb216afe89118c89114040a09972921cf559cb0b67476322b0876cd",
    },
    "fridge-3day": {
        "run.csv": "634da014770b4fd39051b03ab44ed8d8fee4ec01bfccf11d602b94e60f62ea07",
        "run.truth.csv": "2f9d1cab395f7c2c8fc1b9c3aa4d9848005c1bf00ca7b97beb8a24d700335727",
        "run.truth.json": "95007b3f784b42d90ecf34b430d668a748d5c042bbafb2c288e61b066f994627",
    },
    "fridge-3day-short": {
        "run.csv": "3f1c07ea081ce10daa834e0db66babf304769da13addc81bc8116f083c7f7a6d",
        "run.truth.csv": "dbd180ae9dcd9713254c7669172d053e991f81495b643ecc0ee1457ead977f1c",
        "run.truth.json": "05d587c922786b5c32aa3eee2eb2c08f016c2c43545644280e2b4548e1e014c7",
    },
    "fridge-overrides": {
        "run.csv": "2e3bd3f72a4b37f9eb1d2e847c7d4e5c7cca3fd78cf13060de72447bc5b469c6",
        "run.truth.csv": "d0dbcf7299a5d5464f4b5905714dd22d8d58909731e98b7632cab48c7080934f",
        "run.truth.json": "23c938fc91aed0c9b2aa499d6bc3938fb71a5290dbb75e0527ed7936589a9db7",
    },
    "pan-cold": {
        "run.csv": "18c55234f5c8daf223b37230f5e3c78b95c87a12da252bd768608617a4d3ad0a",
        "run.truth.csv": "e0bb2a15384c44dd746b0eeb2b9c679de3ed9110619eaf5a393823106995cad2",
        "run.truth.json": "0a4604ce34f54ad0f7d7f3883ece6e2f3946cdf318842b6acec794717c649fcc",
        "run_reflog.csv": "2a00df6e85ee2be8132fd4f4483dc8a4e6c9f32189342b6d70c958d79fc5d36a",
    },
    "pan-cold-lag": {
        "run.csv": "81727878d069913b56c841749218bb82afcbea616becda34ce057b851fa58773",
        "run.truth.csv": "17c7222321062740934cc05283bd5d2afdc5e5f53136343f6ee0b72799275b9a",
        "run.truth.json": "4da71daea80d9618e2e3fa2500d507de1a18e4c658e05df72033b3868c7ad3b6",
        "run_reflog.csv": "4eeafd10dd6838a22c22588e1c6348222b96db65fb22c729574e48b8eaf91804",
    },
    "pan-cold-overrides": {
        "run.csv": "2ec10d33daf8b7e5974daaace77ee04dcdc4809fc97ae303fc97fcac51894b3e",
        "run.truth.csv": "96d1432c5bafe45561e442b4f7ef3e3546726e39301162098c9ccebc1f234ccf",
        "run.truth.json": "43e18c16bf278348f18b2e8cac6bc10238647447184ad2e7964cb81b14186756",
    },
    "timestamp": {
        "run.csv": "b3f12767f28797f452ffefcd04de2bbbd619eb23fb35e37c124cd9d08d8ccebf",
        "run.truth.csv": "800a3eba3bc9e66a0dd458aea44143419205ef8269dbf6982857c915c5adabdd",
        "run.truth.json": "2cd8076d72e17faace5ff4b801f06e49c36ea4a89d2366661a42e3d398d22c4b",
    },
}


def _digests(case: str, tmp_path) -> dict[str, str]:
    out = tmp_path / case
    out.mkdir()
    result = CliRunner().invoke(app, ["simulate", *CASES[case], "--seed", "7",
                                      "-o", str(out / "run.csv"), "--json"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)
    digests = {}
    for path in sorted(out.iterdir()):
        data = path.read_bytes().replace(str(out).encode(), b"OUT")
        digests[path.name] = hashlib.sha256(data).hexdigest()
    return digests


@pytest.mark.parametrize("case", sorted(CASES))
def test_logger_files_are_unchanged(case, tmp_path):
    digests = _digests(case, tmp_path)
    assert digests == EXPECTED[case]
