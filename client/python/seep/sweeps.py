"""A sweep as a table: one row per job with its position, id, state, the value of every swept
parameter and the chosen result metrics — the rows of `seep sweep show --csv`, as a list of
dicts or, when pandas is installed, a DataFrame."""
from .states import state_name


def _setting_value(setting):
    kind = setting.WhichOneof("value")
    return getattr(setting, kind) if kind else None


def metric_columns(sweep, requested):
    """`requested` when given, else every metric any job has, sorted (as the CLI). A requested
    metric no job has is a ValueError naming the ones there are."""
    present = sorted({name for member in sweep.jobs for name in member.job.result.metrics})
    if requested is None:
        return present
    requested = list(requested)
    unknown = [name for name in requested if present and name not in present]
    if unknown:
        raise ValueError("metrics %s: no job of sweep %s has this metric (they have: %s)" %
                         (", ".join(unknown), sweep.id, ", ".join(present)))
    return requested


def sweep_rows(sweep, metrics):
    """A seep.v1.SweepStatus as a list of dicts; a metric a job does not have (yet) is None."""
    rows = []
    for member in sweep.jobs:
        row = {"position": member.position, "job_id": member.job.id,
               "state": state_name(member.job.state)}
        for path, setting in zip(sweep.parameters, member.settings):
            row[path] = _setting_value(setting)
        values = member.job.result.metrics
        for name in metrics:
            row[name] = values[name] if name in values else None
        rows.append(row)
    return rows


def as_table(rows, columns, use_pandas):
    """The rows as a pandas DataFrame (columns in this order) when pandas is installed and
    use_pandas is true, else the list itself."""
    if not use_pandas:
        return rows
    try:
        import pandas
    except ImportError:
        return rows
    return pandas.DataFrame(rows, columns=columns)
