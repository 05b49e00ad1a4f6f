"""Client: seepd's job service for scripts and notebooks. Submit a scene, wait for it with a
progress bar, read its metrics, time series and fields as numpy arrays; the same for sweeps, whose
jobs come back as a table. Every call takes the client's timeout (seconds) except the waits; a
failed call raises a SeepError subclass (errors.py) with the server's status and message."""
import os
import secrets
import time

import grpc

from . import arrays, connection, errors, messages, sweeps
from .progress import progress_bar
from .states import TERMINAL, state_name
from .v1 import job_service_pb2 as pb, job_service_pb2_grpc, scene_pb2, sweep_pb2


def _new_request_id():
    # An idempotency key per submission, as the CLI makes (r-<16 hex digits>).
    return "r-" + secrets.token_hex(8)


def _job_status(job):
    p = job.progress
    return "%s step %d t=%.6g s" % (state_name(job.state), p.step, p.time_s)


def _sweep_status(sweep):
    c = sweep.counts
    return "%d jobs: %d queued, %d running, %d succeeded, %d failed, %d cancelled" % (
        len(sweep.jobs), c.queued, c.running, c.succeeded, c.failed, c.cancelled)


def _remaining(deadline):
    return None if deadline is None else max(deadline - time.monotonic(), 0.0)


class Client:
    """A connection to one seepd, with the options of the `seep` CLI: server (default
    $SEEP_SERVER or 127.0.0.1:50051), token (default $SEEP_TOKEN) or token_file (wins), tls (the
    system's root certificates) or tls_ca (a PEM file to trust), timeout (seconds per call)."""

    def __init__(self, server=None, *, token=None, token_file=None, tls=False, tls_ca=None,
                 timeout=10.0):
        self.server = server or os.environ.get("SEEP_SERVER") or connection.DEFAULT_SERVER
        self.timeout = timeout
        self._metadata = connection.call_metadata(connection.read_token(token, token_file))
        self._channel = connection.open_channel(self.server, tls, tls_ca)
        self._stub = job_service_pb2_grpc.SeepServiceStub(self._channel)

    def close(self):
        self._channel.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _call(self, method, request, what):
        try:
            return getattr(self._stub, method)(request, timeout=self.timeout,
                                               metadata=self._metadata)
        except grpc.RpcError as error:
            raise errors.from_rpc_error(error, what, self.server) from None

    def _queue(self, method, request, submitted, name, request_id, priority, labels, what):
        """SubmitJob or SubmitSweep: the options both take, set on the request; `submitted` is
        the request's scene or sweep (a copy of the caller's), which `name` renames."""
        if name is not None:
            submitted.name = name
        request.request_id = request_id or _new_request_id()
        request.priority = priority
        request.labels.update(labels or {})
        return self._call(method, request, what)

    # Jobs.

    def submit(self, scene, *, name=None, request_id=None, priority=0, labels=None):
        """Queues a scene (a seep.v1.Scene, a dict, text-format or JSON text, or a .textproto /
        .json file path) and returns the job id. A scene the server rejects raises
        InvalidArgument whose message names the field."""
        request = pb.SubmitJobRequest(scene=messages.to_message(scene, scene_pb2.Scene, "scene"))
        return self._queue("SubmitJob", request, request.scene, name, request_id, priority,
                           labels, "submit").job.id

    def fork(self, from_job_id, scene, *, from_step=None, name=None, request_id=None, priority=0,
             labels=None):
        """Queues a fork of job from_job_id and returns its id: `scene` (as for submit) is that
        job's scene with new stages after the one its checkpoint at from_step (None = its newest)
        is in, and the fork starts exactly from that checkpoint. A scene that differs elsewhere,
        a calibration job or an unknown step raises InvalidArgument naming the field."""
        request = pb.SubmitJobRequest(scene=messages.to_message(scene, scene_pb2.Scene, "scene"),
                                      from_job_id=from_job_id)
        if from_step is not None:
            request.from_step = from_step
        return self._queue("SubmitJob", request, request.scene, name, request_id, priority,
                           labels, "fork").job.id

    def job(self, job_id):
        """The seep.v1.Job as it is now (state, progress, error, ...)."""
        return self._call("GetJob", pb.GetJobRequest(id=job_id), "job").job

    def wait(self, job_id, *, timeout=None, progress=True, check=True):
        """Follows the job until it finishes (WatchJob) with a progress bar, and returns the final
        seep.v1.Job. check: a FAILED or CANCELLED job raises JobFailed. timeout (seconds, None =
        no limit) raises TimeoutError."""
        deadline = None if timeout is None else time.monotonic() + timeout
        bar = progress_bar("job " + job_id, progress)
        try:
            job = self.job(job_id)
            while job.state not in TERMINAL:
                try:
                    # The stream ends at a terminal state; should it end before (a server shutting
                    # down), the loop watches again.
                    for event in self._stub.WatchJob(pb.WatchJobRequest(id=job_id),
                                                     timeout=_remaining(deadline),
                                                     metadata=self._metadata):
                        job = event.job
                        bar.update(job.progress.fraction_done, _job_status(job))
                except grpc.RpcError as error:
                    if error.code() == grpc.StatusCode.DEADLINE_EXCEEDED:
                        raise TimeoutError("job %s: not finished after %g s (%s)" %
                                           (job_id, timeout, _job_status(job))) from None
                    raise errors.from_rpc_error(error, "wait", self.server) from None
                if job.state not in TERMINAL:
                    time.sleep(0.1)
            bar.update(1.0 if job.state == pb.JOB_STATE_SUCCEEDED else job.progress.fraction_done,
                       _job_status(job))
        finally:
            bar.close()
        if check and job.state != pb.JOB_STATE_SUCCEEDED:
            raise errors.JobFailed(job, state_name(job.state))
        return job

    def result(self, job_id):
        """A SUCCEEDED job's Result: metrics (dict), series (column -> np.ndarray), wall time,
        state hash. Any other state raises FailedPrecondition."""
        response = self._call("GetResult", pb.GetResultRequest(id=job_id), "result")
        return arrays.result_from_proto(response.job_id, response.result)

    def metrics(self, job_id):
        return self.result(job_id).metrics

    def series(self, job_id, *, structured=False):
        """The time series: a dict column -> float64 array, or one numpy structured array."""
        columns = self.result(job_id).series
        return arrays.structured(columns) if structured else columns

    def fields(self, job_id, step=0):
        """Particles, domains, pipes, bonds and walls at a checkpoint (0 = the newest, a finished
        job's final state) as numpy arrays (arrays.Fields)."""
        response = self._call("GetJobFields", pb.GetJobFieldsRequest(job_id=job_id, step=step),
                              "fields")
        return arrays.fields_from_proto(response)

    def cancel(self, job_id):
        """A QUEUED job is cancelled at once, a RUNNING one at its next step (the returned Job
        may still be RUNNING with cancel_requested); a finished one raises FailedPrecondition."""
        return self._call("CancelJob", pb.CancelJobRequest(id=job_id), "cancel").job

    def resume(self, job_id):
        """A FAILED or CANCELLED job queued again from its newest checkpoint; returns the Job."""
        return self._call("ResumeJob", pb.ResumeJobRequest(id=job_id), "resume").job

    def delete(self, job_id):
        """Removes a finished job with its result and checkpoint files."""
        self._call("DeleteJob", pb.DeleteJobRequest(id=job_id), "delete")

    # Sweeps.

    def submit_sweep(self, sweep, *, name=None, request_id=None, priority=0, labels=None):
        """Queues a seep.v1.Sweep (message, dict, text, JSON or file path, as submit) and returns
        the sweep id. A bad axis path or value raises InvalidArgument naming it."""
        request = pb.SubmitSweepRequest(sweep=messages.to_message(sweep, sweep_pb2.Sweep, "sweep"))
        return self._queue("SubmitSweep", request, request.sweep, name, request_id, priority,
                           labels, "sweep submit").sweep.id

    def sweep(self, sweep_id):
        """The seep.v1.SweepStatus: every job's state, progress and metrics."""
        return self._call("GetSweep", pb.GetSweepRequest(id=sweep_id), "sweep").sweep

    def wait_sweep(self, sweep_id, *, timeout=None, progress=True, poll_s=0.5):
        """Polls the sweep until none of its jobs is QUEUED or RUNNING, with one progress bar for
        the sweep; returns the final SweepStatus (failed jobs show in its counts and table)."""
        deadline = None if timeout is None else time.monotonic() + timeout
        bar = progress_bar("sweep " + sweep_id, progress)
        try:
            while True:
                status = self.sweep(sweep_id)
                bar.update(status.fraction_done, _sweep_status(status))
                if status.counts.queued == 0 and status.counts.running == 0:
                    return status
                if deadline is not None and time.monotonic() >= deadline:
                    raise TimeoutError("sweep %s: not finished after %g s (%s)" %
                                       (sweep_id, timeout, _sweep_status(status)))
                time.sleep(poll_s)
        finally:
            bar.close()

    def sweep_table(self, sweep_id, metrics=None, *, pandas=True):
        """One row per job: position, job_id, state, every swept parameter, then the metrics
        (default: every metric any job has, sorted; None where a job has none) — a pandas
        DataFrame when pandas is installed (and pandas=True), else a list of dicts."""
        status = self.sweep(sweep_id)
        names = sweeps.metric_columns(status, metrics)
        columns = ["position", "job_id", "state"] + list(status.parameters) + names
        return sweeps.as_table(sweeps.sweep_rows(status, names), columns, pandas)

    def cancel_sweep(self, sweep_id):
        """cancel() on every QUEUED or RUNNING job of the sweep; returns the SweepStatus."""
        return self._call("CancelSweep", pb.CancelSweepRequest(id=sweep_id), "sweep cancel").sweep

    def resume_sweep(self, sweep_id):
        """resume() on every FAILED or CANCELLED job of the sweep; returns the SweepStatus."""
        return self._call("ResumeSweep", pb.ResumeSweepRequest(id=sweep_id), "sweep resume").sweep

    def delete_sweep(self, sweep_id):
        """Removes a finished sweep with all its jobs."""
        self._call("DeleteSweep", pb.DeleteSweepRequest(id=sweep_id), "sweep delete")
