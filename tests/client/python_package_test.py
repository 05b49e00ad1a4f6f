#!/usr/bin/env python3
"""The seep Python package (client/python) against a real seepd and the seep CLI: what the
package returns must be exactly what the CLI prints for the same job — metrics and time series as
`seep result --json`, fields as `seep export --format csv`, a sweep's table as
`seep sweep show --csv` (every double equal, not close). Also: a bad scene raises InvalidArgument
naming the field, and scenes given as text, JSON, dict and file path run alike.

Usage: python_package_test.py --seepd P --seep P --examples DIR --work-dir DIR [unittest args]
Exit code 0 = passed, 1 = failed, 77 = skipped (only when python3-grpcio or python3-numpy is
missing).
"""
import argparse
import contextlib
import csv
import io
import json
import math
import os
import pathlib
import shutil
import subprocess
import sys
import unittest

try:
    import grpc  # noqa: F401
    import numpy as np
except ImportError as missing:
    print("SKIPPED: %s (apt-get install python3-grpcio python3-numpy)" % missing)
    sys.exit(77)

from google.protobuf import json_format, text_format

import seep
from seep.v1 import scene_pb2
from seepd_process import Seepd

ARGS = None
EXAMPLES = ("darcy_square_lattice.textproto", "transient_1d.textproto")


def json_double(value):
    # Proto3 JSON writes NaN and the infinities as strings.
    return float(value)


def read_csv(path):
    """A CSV file of the export as column -> list of its cells (text)."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    return {name: [row[c] for row in body] for c, name in enumerate(header)}


def doubles(cells):
    return np.array([float(c) for c in cells], dtype=np.float64)


class PackageTest(unittest.TestCase):
    def setUp(self):
        self.seepd = Seepd(ARGS.seepd, ARGS.work_dir)
        self.client = seep.Client(self.seepd.address, timeout=30)

    def tearDown(self):
        self.client.close()
        self.seepd.stop()

    def cli(self, *args):
        """The CLI's stdout for these arguments (it must exit 0)."""
        run = subprocess.run([ARGS.seep, "--server", self.seepd.address] + list(args),
                             capture_output=True, text=True, timeout=60)
        self.assertEqual(run.returncode, 0, "seep %s: %s" % (" ".join(args), run.stderr))
        return run.stdout

    def run_example(self, name):
        job = self.client.submit(os.path.join(ARGS.examples, name))
        final = self.client.wait(job, timeout=120, progress=False)
        self.assertEqual(final.state, seep.v1.job_service_pb2.JOB_STATE_SUCCEEDED)
        return job

    def assert_same_array(self, actual, expected, what):
        self.assertGreater(len(expected), 0, what + ": nothing to compare")
        self.assertEqual(actual.shape, expected.shape, what)
        # Bit-equal doubles: array_equal with NaN equal to NaN, and the signs of zeros compared.
        self.assertTrue(np.array_equal(actual, expected, equal_nan=True), what)
        self.assertTrue(np.array_equal(np.signbit(actual), np.signbit(expected)), what)

    def test_ResultsAndSeriesEqualSeepResultJson(self):
        for example in EXAMPLES:
            with self.subTest(example=example):
                job = self.run_example(example)
                result = self.client.result(job)
                cli = json.loads(self.cli("result", job, "--json"))["result"]
                expected_metrics = {k: json_double(v) for k, v in cli["metrics"].items()}
                self.assertGreater(len(expected_metrics), 0)
                self.assertEqual(set(result.metrics), set(expected_metrics))
                for name, value in expected_metrics.items():
                    self.assertTrue(value == result.metrics[name] or
                                    (math.isnan(value) and math.isnan(result.metrics[name])),
                                    "%s: %r != %r" % (name, result.metrics[name], value))
                self.assertEqual(self.client.metrics(job), result.metrics)
                self.assertEqual(result.state_sha256, cli["state_sha256"])
                self.assertEqual(result.wall_time_s, json_double(cli["wall_time_s"]))

                columns = cli["series"]["columns"]
                values = np.array([json_double(v) for v in cli["series"]["values"]])
                self.assertEqual(list(result.series), columns)
                rows = values.reshape(-1, len(columns))
                structured = self.client.series(job, structured=True)
                self.assertEqual(list(structured.dtype.names), columns)
                for c, name in enumerate(columns):
                    self.assert_same_array(result.series[name], rows[:, c], "series " + name)
                    self.assert_same_array(structured[name], rows[:, c], "structured " + name)

    def test_FieldsEqualSeepExportCsv(self):
        for example in EXAMPLES:
            with self.subTest(example=example):
                job = self.run_example(example)
                fields = self.client.fields(job)
                out = os.path.join(ARGS.work_dir, "export-" + job)
                exported = json.loads(self.cli("export", job, "--out", out, "--format", "csv",
                                               "--json"))
                self.assertEqual([int(s) for s in exported["steps"]], [fields.step])
                self.assertIn(fields.step, fields.available_steps)
                for group, stem in (("particles", "particles"), ("domains", "domains"),
                                    ("pipes", "pipes")):
                    expected = read_csv(os.path.join(out, "%s_%d.csv" % (stem, fields.step)))
                    arrays = getattr(fields, group)
                    missing = set(expected) - set(arrays)
                    self.assertFalse(missing, "%s: not in the package's arrays" % group)
                    for name, cells in expected.items():
                        self.assert_same_array(arrays[name].astype(np.float64), doubles(cells),
                                               "%s %s" % (group, name))
                # Every domain column the export writes, no more (the analytic ones only where
                # the scene has them).
                self.assertEqual(set(fields.domains), set(read_csv(os.path.join(
                    out, "domains_%d.csv" % fields.step))))
                offsets = fields.domain_loops["offsets"]
                self.assertEqual(len(offsets), len(fields.domains["pressure_pa"]) + 1)
                self.assertEqual(offsets[-1], len(fields.domain_loops["particles"]))
                series = read_csv(os.path.join(out, "series.csv"))
                result = self.client.result(job)
                self.assertEqual(list(result.series), list(series))
                for name, cells in series.items():
                    self.assert_same_array(result.series[name], doubles(cells), "series " + name)

    def test_BadSceneRaisesInvalidArgumentNamingTheField(self):
        with open(os.path.join(ARGS.examples, EXAMPLES[0])) as f:
            text = f.read().replace("viscosity_pa_s: 1e-3", "viscosity_pa_s: -1")
        bad_file = os.path.join(ARGS.work_dir, "bad.textproto")
        with open(bad_file, "w") as f:
            f.write(text)
        with self.assertRaises(seep.InvalidArgument) as raised:
            self.client.submit(text)
        error = raised.exception
        self.assertIsInstance(error, ValueError)
        self.assertEqual(error.code, "INVALID_ARGUMENT")
        self.assertTrue(error.details.startswith("scene.fluid.viscosity_pa_s"), error.details)
        self.assertIn("scene.fluid.viscosity_pa_s", str(error))
        # The CLI prints the server's message after FILE:LINE: — the same words.
        run = subprocess.run([ARGS.seep, "--server", self.seepd.address, "submit", bad_file],
                             capture_output=True, text=True, timeout=60)
        self.assertEqual(run.returncode, 3, run.stderr)
        self.assertTrue(run.stderr.strip().endswith(": " + error.details), run.stderr)
        # Nothing was queued by either.
        self.assertEqual(json.loads(self.cli("list", "--json")).get("jobs", []), [])

        # Text that does not parse: a ValueError with the line, before any call.
        with self.assertRaisesRegex(ValueError, r"^scene text:2:"):
            self.client.submit('name: "x"\nfluid { viscosity_pa_s: }\n')
        with self.assertRaisesRegex(ValueError, "no_such_field"):
            self.client.submit({"name": "x", "no_such_field": 1})
        with self.assertRaisesRegex(ValueError, "missing.textproto: cannot be read"):
            self.client.submit(os.path.join(ARGS.work_dir, "missing.textproto"))
        with self.assertRaises(seep.NotFound):
            self.client.result("j-0000000000000000")
        with self.assertRaises(seep.InvalidArgument) as raised:
            self.client.submit_sweep({"name": "s", "scene": json_format.MessageToDict(
                text_format.Parse(text.replace("-1", "1e-3"), scene_pb2.Scene())),
                "combine": "SWEEP_COMBINE_PRODUCT",
                "axes": [{"path": "fluid.no_such_field", "numbers": [1.0]}]})
        self.assertIn("fluid.no_such_field", raised.exception.details)

        # Nobody listening: Unavailable naming the address.
        unreachable = seep.Client("127.0.0.1:1", timeout=5)
        with self.assertRaisesRegex(seep.Unavailable, "127.0.0.1:1 unreachable"):
            unreachable.job("j-0000000000000000")
        unreachable.close()
        empty = os.path.join(ARGS.work_dir, "empty-token")
        open(empty, "w").close()
        with self.assertRaisesRegex(ValueError, "token_file .*empty-token: is empty"):
            seep.Client(self.seepd.address, token_file=empty)

    def test_ForkContinuesAStagedJob(self):
        """Client.fork: a staged job's final state continued with a stage more, parent and child
        linked both ways; a fork whose packing differs, or of a step without a checkpoint, raises
        InvalidArgument naming the field and queues nothing."""
        staged = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "service",
                              "data", "staged_box.textproto")
        parent = self.client.submit(staged)
        done = self.client.wait(parent, timeout=120, progress=False)
        with open(staged) as f:
            scene = text_format.Parse(f.read(), scene_pb2.Scene())
        hold = scene.stages.add(name="hold")
        hold.end.add(duration_s=1e-3)
        fork = self.client.fork(parent, scene, name="with-hold")
        final = self.client.wait(fork, timeout=120, progress=False)
        self.assertEqual(final.name, "with-hold")
        self.assertEqual(final.parent_job_id, parent)
        # Unset from_step: the newest checkpoint, a finished job's final state.
        self.assertEqual(final.parent_step, int(done.result.metrics["steps"]))
        self.assertEqual(self.client.metrics(fork)["stages_ended"], 4.0)
        self.assertEqual(list(self.client.job(parent).child_job_ids), [fork])
        scene.packing.lattice.rows = 9
        with self.assertRaises(seep.InvalidArgument) as raised:
            self.client.fork(parent, scene, from_step=final.parent_step)
        self.assertTrue(raised.exception.details.startswith("scene.packing:"),
                        raised.exception.details)
        with self.assertRaises(seep.InvalidArgument) as raised:
            self.client.fork(parent, scene, from_step=1)
        self.assertTrue(raised.exception.details.startswith("from_step:"),
                        raised.exception.details)
        self.assertEqual(len(json.loads(self.cli("list", "--json"))["jobs"]), 2)

    def test_TokenAndTlsAsTheCli(self):
        folder = ARGS.work_dir + "-secure"
        os.makedirs(folder, exist_ok=True)
        self.addCleanup(shutil.rmtree, folder, True)  # last: after seepd has stopped
        cert, key = os.path.join(folder, "cert.pem"), os.path.join(folder, "key.pem")
        subprocess.run(["/usr/bin/openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes",
                        "-days", "1", "-subj", "/CN=localhost", "-addext",
                        "subjectAltName=DNS:localhost,IP:127.0.0.1", "-keyout", key, "-out",
                        cert], check=True, capture_output=True)
        token_file = os.path.join(folder, "token")
        with open(os.open(token_file, os.O_WRONLY | os.O_CREAT, 0o600), "w") as f:
            f.write("s3cret-token\n")
        secure = Seepd(ARGS.seepd, os.path.join(folder, "seepd"),
                       ["--tls-cert", cert, "--tls-key", key, "--token-file", token_file])
        self.addCleanup(secure.stop)

        scene = os.path.join(ARGS.examples, EXAMPLES[0])
        with seep.Client(secure.address, tls_ca=cert, token_file=token_file) as client:
            job = client.submit(scene)
            self.assertEqual(client.wait(job, progress=False).id, job)
            self.assertEqual(len(client.result(job).state_sha256), 64)
        with seep.Client(secure.address, tls_ca=cert, token="s3cret-token") as client:
            self.assertEqual(client.job(job).id, job)
        previous = os.environ.get("SEEP_TOKEN")
        os.environ["SEEP_TOKEN"] = "s3cret-token"
        try:
            with seep.Client(secure.address, tls_ca=cert) as client:
                self.assertEqual(client.job(job).id, job)  # the token from SEEP_TOKEN
        finally:
            os.environ.pop("SEEP_TOKEN")
            if previous is not None:
                os.environ["SEEP_TOKEN"] = previous
        with seep.Client(secure.address, tls_ca=cert, token="") as client:
            with self.assertRaises(seep.Unauthenticated):
                client.job(job)
        with seep.Client(secure.address, tls_ca=cert, token="wrong") as client:
            with self.assertRaises(seep.Unauthenticated):
                client.job(job)
        # Plaintext to a TLS server, or TLS that does not trust its certificate: no handshake.
        for options in ({}, {"tls": True}):
            with seep.Client(secure.address, token="s3cret-token", timeout=3, **options) as client:
                with self.assertRaises((seep.Unavailable, TimeoutError)):
                    client.job(job)
        with self.assertRaisesRegex(ValueError, "tls_ca .*token: is not a PEM certificate"):
            seep.Client(secure.address, tls_ca=token_file)
        with self.assertRaisesRegex(ValueError, "token: only visible ASCII"):
            seep.Client(secure.address, token="two words")

    def test_ScenesFromTextJsonDictAndFile(self):
        path = os.path.join(ARGS.examples, EXAMPLES[0])
        with open(path) as f:
            text = f.read()
        message = text_format.Parse(text, scene_pb2.Scene())
        forms = {"path": path, "pathlib": pathlib.Path(path), "text": text,
                 "json": json_format.MessageToJson(message),
                 "dict": json_format.MessageToDict(message), "message": message}
        hashes = {}
        for form, scene in forms.items():
            job = self.client.submit(scene, name="from-" + form)
            bar = io.StringIO()  # the progress bar (tqdm's or the plain line) writes to stderr
            with contextlib.redirect_stderr(bar):
                self.assertEqual(self.client.wait(job).name, "from-" + form)
            self.assertIn("job " + job, bar.getvalue())
            self.assertIn("SUCCEEDED", bar.getvalue())
            hashes[form] = self.client.result(job).state_sha256
        self.assertEqual(len(set(hashes.values())), 1, hashes)
        # The plain line used without tqdm, into a log (not a terminal): the first and last lines.
        log = io.StringIO()
        with contextlib.redirect_stderr(log):
            line = seep.progress.StderrLine("job j-1")
            for fraction in (0.0, 0.5, 1.0):
                line.update(fraction, "RUNNING")
            line.close()
        self.assertEqual(log.getvalue(), "job j-1   0.0%  RUNNING\njob j-1 100.0%  RUNNING\n")
        self.assertEqual(len(hashes["path"]), 64)

        # A JSON file, the way the CLI reads .json.
        json_file = os.path.join(ARGS.work_dir, "scene.json")
        with open(json_file, "w") as f:
            f.write(forms["json"])
        job = self.client.submit(json_file)
        self.client.wait(job, progress=False)
        self.assertEqual(self.client.result(job).state_sha256, hashes["path"])

    def test_SweepTableEqualsSeepSweepShowCsv(self):
        sweep = self.client.submit_sweep(os.path.join(ARGS.examples, "sweep_darcy.textproto"))
        status = self.client.wait_sweep(sweep, timeout=150, progress=False)
        self.assertEqual(status.counts.succeeded, 6)
        rows = self.client.sweep_table(sweep, pandas=False)
        with open(os.path.join(ARGS.work_dir, "show.csv"), "w") as f:
            f.write(self.cli("sweep", "show", sweep, "--csv"))
        with open(os.path.join(ARGS.work_dir, "show.csv"), newline="") as f:
            expected = list(csv.DictReader(f))
        self.assertEqual(len(rows), 6)
        self.assertEqual(len(expected), 6)
        self.assertEqual(list(rows[0]), list(expected[0]))
        self.assertIn("aperture.residual_aperture_m", rows[0])
        self.assertIn("permeability_m2", rows[0])
        for row, cli_row in zip(rows, expected):
            self.assertEqual(row["position"], int(cli_row["position"]))
            self.assertEqual(row["job_id"], cli_row["job_id"])
            self.assertEqual(row["state"], cli_row["state"])
            for name in list(row)[3:]:
                self.assertEqual(row[name], float(cli_row[name]), name)
        # Two chosen metrics, in the order given; an unknown one names the ones there are.
        chosen = self.client.sweep_table(sweep, ["permeability_m2", "inflow_m2_per_s"],
                                         pandas=False)
        self.assertEqual(list(chosen[0])[-2:], ["permeability_m2", "inflow_m2_per_s"])
        with self.assertRaisesRegex(ValueError, "no_such_metric: .*permeability_m2"):
            self.client.sweep_table(sweep, ["no_such_metric"])
        try:
            import pandas
        except ImportError:
            self.assertEqual(self.client.sweep_table(sweep), rows)
            return
        frame = self.client.sweep_table(sweep)
        self.assertIsInstance(frame, pandas.DataFrame)
        self.assertEqual(list(frame.columns), list(rows[0]))
        self.assertEqual(frame.to_dict("records"), rows)

    def test_CancelResumeDeleteJobsAndSweeps(self):
        job = self.run_example(EXAMPLES[0])
        for refused in (self.client.cancel, self.client.resume):
            with self.assertRaisesRegex(seep.FailedPrecondition, job):
                refused(job)  # a SUCCEEDED job is neither cancelled nor resumed
        self.client.delete(job)
        with self.assertRaises(seep.NotFound):
            self.client.job(job)

        # A sweep queued behind a job of 300 x 300 disks (half a second on the one worker, far
        # longer than the calls below): all six of its jobs are cancelled while QUEUED.
        with open(os.path.join(ARGS.examples, EXAMPLES[0])) as f:
            big = f.read().replace("columns: 60 rows: 40", "columns: 300 rows: 300")
        long_job = self.client.submit(big, priority=1000)
        sweep = self.client.submit_sweep(os.path.join(ARGS.examples, "sweep_darcy.textproto"),
                                         priority=-1000)
        status = self.client.cancel_sweep(sweep)
        self.assertEqual(status.counts.cancelled, 6)
        with self.assertRaisesRegex(seep.JobFailed, "ended CANCELLED") as raised:
            self.client.wait(status.jobs[0].job.id, progress=False)
        self.assertEqual(raised.exception.job.state, seep.v1.job_service_pb2.JOB_STATE_CANCELLED)
        with self.assertRaisesRegex(TimeoutError, "job %s: not finished after 0.05 s" % long_job):
            self.client.wait(long_job, timeout=0.05, progress=False)
        # Queued: cancelled at once; running: asked to stop (a steady solve may still finish).
        cancelled = self.client.cancel(long_job)
        self.assertTrue(cancelled.cancel_requested or
                        cancelled.state == seep.v1.job_service_pb2.JOB_STATE_CANCELLED, cancelled)
        self.client.wait(long_job, progress=False, check=False)
        self.assertEqual(self.client.resume_sweep(sweep).id, sweep)
        self.assertEqual(self.client.wait_sweep(sweep, timeout=150, progress=False)
                         .counts.succeeded, 6)
        self.client.delete_sweep(sweep)
        with self.assertRaises(seep.NotFound):
            self.client.sweep(sweep)
        self.assertEqual(self.client.job(long_job).id, long_job)  # not a job of the sweep


def main():
    global ARGS
    parser = argparse.ArgumentParser()
    for option in ("--seepd", "--seep", "--examples", "--work-dir"):
        parser.add_argument(option, required=True)
    ARGS, rest = parser.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)


if __name__ == "__main__":
    main()
