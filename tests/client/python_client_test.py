#!/usr/bin/env python3
"""A gRPC client that shares no code with seep's C++: Debian's python3-grpcio with stubs that
protoc generated from proto/seep/v1/*.proto at build time (PYTHONPATH points at them; they sit
inside the Python package, client/python, whose import needs numpy).

It starts a real seepd on a free loopback port, submits a small square-lattice scene, polls GetJob
until the job is SUCCEEDED, reads GetResult and checks the permeability against the exact value
k = a0^3 / (24 R) (docs/physics.md §1.3). Exit code 0 = passed, 1 = failed, 77 = skipped (only
when python3-grpcio or python3-numpy is not installed; CTest reports it as skipped).
"""
import argparse
import sys
import time

try:
    import grpc
    import numpy  # noqa: F401 (the seep package around the stubs imports it)
except ImportError as missing:
    print("SKIPPED: %s (apt-get install python3-grpcio python3-numpy)" % missing)
    sys.exit(77)

from google.protobuf import text_format  # python3-protobuf, a dependency of python3-grpcio

from seep.v1 import job_service_pb2, job_service_pb2_grpc, scene_pb2
from seepd_process import Seepd, SeepdError

# 12 x 8 touching disks, R = 1 mm, a0 = 10 um: every pipe has aperture a0, so the permeability
# along x is exactly a0^3 / (24 R) (the lattice test of docs/physics.md §1.3).
SCENE = """
name: "python-client-lattice"
packing { lattice { kind: LATTICE_KIND_SQUARE columns: 12 rows: 8 radius_m: 1e-3 } }
fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2.2e9 }
aperture { residual_aperture_m: 1e-5 reference_force_n: 1e3 gap_multiplier: 0.5 }
boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 outlet_pressure_pa: 0 }
solver { kind: SOLVER_KIND_STEADY }
"""
A0 = 1e-5
RADIUS = 1e-3


def fail(message):
    print("FAILED: " + message)
    sys.exit(1)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--seepd", required=True)
    parser.add_argument("--work-dir", required=True)
    args = parser.parse_args()

    try:
        server = Seepd(args.seepd, args.work_dir)
    except SeepdError as error:
        fail(str(error))
    try:
        with grpc.insecure_channel(server.address) as channel:
            grpc.channel_ready_future(channel).result(timeout=30)
            stub = job_service_pb2_grpc.SeepServiceStub(channel)

            scene = text_format.Parse(SCENE, scene_pb2.Scene())
            submitted = stub.SubmitJob(
                job_service_pb2.SubmitJobRequest(scene=scene, request_id="python-client-1"),
                timeout=10)
            job_id = submitted.job.id
            if not submitted.created or not job_id.startswith("j-"):
                fail("SubmitJob: unexpected response %s" % submitted)
            print("submitted", job_id)

            deadline = time.monotonic() + 60
            terminal = (job_service_pb2.JOB_STATE_SUCCEEDED, job_service_pb2.JOB_STATE_FAILED,
                        job_service_pb2.JOB_STATE_CANCELLED)
            while True:
                job = stub.GetJob(job_service_pb2.GetJobRequest(id=job_id), timeout=10).job
                if job.state in terminal:
                    break
                if time.monotonic() > deadline:
                    fail("job %s still %s after 60 s" %
                         (job_id, job_service_pb2.JobState.Name(job.state)))
                time.sleep(0.05)
            if job.state != job_service_pb2.JOB_STATE_SUCCEEDED:
                fail("job %s ended %s: %s" %
                     (job_id, job_service_pb2.JobState.Name(job.state), job.error.message))

            result = stub.GetResult(job_service_pb2.GetResultRequest(id=job_id), timeout=10)
            k = result.result.metrics["permeability_m2"]
            exact = A0 ** 3 / (24 * RADIUS)
            # The steady solve is direct (sparse Cholesky): only round-off separates k from the
            # exact lattice value, ~1e-13 relative on this size; 1e-9 leaves ample margin.
            relative = abs(k - exact) / exact
            print("permeability_m2 %.12g, exact %.12g, relative error %.3g" % (k, exact, relative))
            if relative > 1e-9:
                fail("permeability %.12g differs from a0^3/(24R) = %.12g by %.3g" %
                     (k, exact, relative))

            # A missing job is NOT_FOUND for any client, not only ours.
            try:
                stub.GetJob(job_service_pb2.GetJobRequest(id="j-0000000000000000"), timeout=10)
                fail("GetJob of a missing job succeeded")
            except grpc.RpcError as error:
                if error.code() != grpc.StatusCode.NOT_FOUND:
                    fail("GetJob of a missing job: %s, expected NOT_FOUND" % error.code())
    finally:
        try:
            server.stop()
        except SeepdError as error:
            fail(str(error))
    print("PASSED")


if __name__ == "__main__":
    main()
