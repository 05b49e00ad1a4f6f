"""Job state names as the CLI prints them ("SUCCEEDED", without the JOB_STATE_ prefix)."""
from .v1 import job_service_pb2

TERMINAL = (job_service_pb2.JOB_STATE_SUCCEEDED, job_service_pb2.JOB_STATE_FAILED,
            job_service_pb2.JOB_STATE_CANCELLED)


def state_name(state):
    return job_service_pb2.JobState.Name(state)[len("JOB_STATE_"):]
