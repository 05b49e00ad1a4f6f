"""Results, time series and fields as numpy arrays: a dict of column name -> np.ndarray (easy to
hand to pandas or matplotlib), or a numpy structured array of the same columns. Values are the
doubles the server sent, unchanged."""
from dataclasses import dataclass, field
from typing import Dict, List

import numpy as np
from google.protobuf.descriptor import FieldDescriptor

Columns = Dict[str, np.ndarray]

_DTYPES = {
    FieldDescriptor.TYPE_DOUBLE: np.float64,
    FieldDescriptor.TYPE_INT32: np.int32,
    FieldDescriptor.TYPE_BOOL: np.bool_,
}

# JobFields' arrays by prefix; a column is named as in `seep export --format csv` (the prefix
# dropped: particles x_m, domains pressure_pa, pipes flow_m2_per_s). Longest prefix first:
# "wall_vertex_" before "wall_".
_GROUPS = (("particle_", "particles"), ("domain_loop_", "domain_loops"), ("domain_", "domains"),
           ("pipe_", "pipes"), ("bond_", "bonds"), ("wall_vertex_", "wall_vertices"),
           ("wall_", "walls"))
_ANALYTIC = ("analytic_pressure_pa", "axis_coordinate_m")


def structured(columns):
    """A dict of equal-length columns as one numpy structured array (one field per column)."""
    names = list(columns)
    lengths = {len(columns[n]) for n in names}
    if len(lengths) > 1:
        raise ValueError("columns of different lengths: %s" %
                         ", ".join("%s %d" % (n, len(columns[n])) for n in names))
    out = np.empty(lengths.pop() if lengths else 0,
                   dtype=[(n, columns[n].dtype) for n in names])
    for n in names:
        out[n] = columns[n]
    return out


def series_columns(series):
    """A seep.v1.TimeSeries (row-major values) as column -> float64 array."""
    width = len(series.columns)
    values = np.array(series.values, dtype=np.float64)
    if width == 0:
        return {}
    if values.size % width:
        raise ValueError("time series: %d values do not fill rows of %d columns" %
                         (values.size, width))
    rows = values.reshape(-1, width)
    return {name: rows[:, c].copy() for c, name in enumerate(series.columns)}


@dataclass
class Result:
    """What a SUCCEEDED job measured: GetResult as Python values."""
    job_id: str
    metrics: Dict[str, float]
    series: Columns
    wall_time_s: float
    state_sha256: str

    def series_array(self):
        return structured(self.series)


def result_from_proto(job_id, result):
    return Result(job_id=job_id, metrics=dict(result.metrics), series=series_columns(result.series),
                  wall_time_s=result.wall_time_s, state_sha256=result.state_sha256)


@dataclass
class Fields:
    """A job's state at one checkpoint (GetJobFields): each group a dict of equal-length columns.
    domain_loops holds offsets (one per domain plus one) and particles (the loops' particle ids,
    ids past the particle count being wall vertices), see proto/seep/v1/job_service.proto."""
    job_id: str
    step: int
    time_s: float
    available_steps: List[int]
    particles: Columns = field(default_factory=dict)
    domains: Columns = field(default_factory=dict)
    domain_loops: Columns = field(default_factory=dict)
    pipes: Columns = field(default_factory=dict)
    bonds: Columns = field(default_factory=dict)
    walls: Columns = field(default_factory=dict)
    wall_vertices: Columns = field(default_factory=dict)
    other: Columns = field(default_factory=dict)  # arrays of a newer server, by proto name
    analytic_kind: str = ""
    axis_name: str = ""
    axis_length_m: float = 0.0


def fields_from_proto(response):
    f = response.fields
    out = Fields(job_id=response.job_id, step=response.step, time_s=response.time_s,
                 available_steps=list(response.available_steps), analytic_kind=f.analytic_kind,
                 axis_name=f.axis_name, axis_length_m=f.axis_length_m)
    for descriptor in f.DESCRIPTOR.fields:
        if descriptor.label != FieldDescriptor.LABEL_REPEATED:
            continue
        prefix, group = next(((p, g) for p, g in _GROUPS if descriptor.name.startswith(p)),
                             ("", "other"))
        name = descriptor.name[len(prefix):]
        if group == "domains" and name in _ANALYTIC and not f.analytic_kind:
            continue  # no analytic pressure in this scene (empty arrays, as the export omits)
        values = getattr(f, descriptor.name)
        getattr(out, group)[name] = np.array(values, dtype=_DTYPES[descriptor.type])
    return out
