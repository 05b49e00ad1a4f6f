"""A progress bar for Client.wait(): tqdm's (tqdm.auto: a widget in notebooks) when tqdm is
installed, else one line on stderr rewritten in place."""
import sys


class _StderrLine:
    def __init__(self, description):
        self._description = description
        self._last = ""

    def update(self, fraction, status):
        line = "%s %5.1f%%  %s" % (self._description, 100.0 * fraction, status)
        if line != self._last:
            sys.stderr.write("\r" + line.ljust(len(self._last)))
            sys.stderr.flush()
            self._last = line

    def close(self):
        if self._last:
            sys.stderr.write("\n")
            sys.stderr.flush()


class _Tqdm:
    def __init__(self, tqdm, description):
        self._bar = tqdm(total=1000, desc=description, unit="‰", leave=True)

    def update(self, fraction, status):
        # tqdm counts integers: the fraction in thousandths.
        self._bar.n = int(round(1000 * min(max(fraction, 0.0), 1.0)))
        self._bar.set_postfix_str(status, refresh=False)
        self._bar.refresh()

    def close(self):
        self._bar.close()


class _Silent:
    def update(self, fraction, status):
        pass

    def close(self):
        pass


def progress_bar(description, enabled=True):
    """An object with update(fraction 0..1, status text) and close()."""
    if not enabled:
        return _Silent()
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return _StderrLine(description)
    return _Tqdm(tqdm, description)
