"""The exceptions of the seep package: a failed call keeps the server's status code and message
(an INVALID_ARGUMENT message starts with the field it is about, e.g.
"scene.fluid.viscosity_pa_s: must be > 0"), so that scripts can catch by kind and people can read
what to fix."""
import grpc


class SeepError(Exception):
    """A call to seepd failed. `code` is the gRPC status name ("NOT_FOUND"), `details` the
    server's message."""

    def __init__(self, code, details, what=""):
        self.code = code
        self.details = details
        super().__init__("%s%s: %s" % (what + ": " if what else "", code, details))


class InvalidArgument(SeepError, ValueError):
    """The server rejected the input (a scene field, a sweep axis, a label): `details` names
    it."""


class NotFound(SeepError, LookupError):
    """No such job or sweep."""


class FailedPrecondition(SeepError):
    """The job or sweep is not in a state that allows the call (e.g. the result of a job that
    has not SUCCEEDED)."""


class Unauthenticated(SeepError, PermissionError):
    """seepd wants a bearer token (token=, token_file= or SEEP_TOKEN) and got none or another."""


class Unavailable(SeepError, ConnectionError):
    """seepd cannot be reached (or a TLS mismatch, which gRPC reports the same way)."""


class JobFailed(SeepError):
    """Client.wait(): the job ended FAILED or CANCELLED; `job` is the final seep.v1.Job."""

    def __init__(self, job, state_name):
        self.job = job
        super().__init__(job.error.code or state_name, job.error.message or "cancelled",
                         "job %s ended %s" % (job.id, state_name))


_BY_CODE = {
    grpc.StatusCode.INVALID_ARGUMENT: InvalidArgument,
    grpc.StatusCode.NOT_FOUND: NotFound,
    grpc.StatusCode.FAILED_PRECONDITION: FailedPrecondition,
    grpc.StatusCode.UNAVAILABLE: Unavailable,
    grpc.StatusCode.UNAUTHENTICATED: Unauthenticated,
}


def from_rpc_error(error, what, server):
    """The SeepError subclass for a grpc.RpcError of the call `what`."""
    code = error.code()
    details = error.details() or ""
    if code == grpc.StatusCode.UNAVAILABLE:
        details = "server %s unreachable: %s" % (server, details)
    if code == grpc.StatusCode.DEADLINE_EXCEEDED:
        return TimeoutError("%s: no answer from %s in time: %s" % (what, server, details))
    return _BY_CODE.get(code, SeepError)(code.name, details, what)
