"""A progress bar for Client.wait(): tqdm's (tqdm.auto: a widget in notebooks) when tqdm is
installed, else one line on stderr rewritten in place."""
import sys
import time


class StderrLine:
    """On a terminal one line rewritten in place; in a log file or pipe a line every few seconds
    (and the last), so that a long run does not fill the log."""

    LOG_EVERY_S = 5.0

    def __init__(self, description):
        self._description = description
        self._tty = sys.stderr.isatty()
        self._last = ""
        self._pending = ""
        self._logged_at = None

    def update(self, fraction, status):
        line = "%s %5.1f%%  %s" % (self._description, 100.0 * fraction, status)
        if self._tty:
            if line != self._last:
                sys.stderr.write("\r" + line.ljust(len(self._last)))
                sys.stderr.flush()
                self._last = line
            return
        now = time.monotonic()
        if self._logged_at is None or now - self._logged_at >= self.LOG_EVERY_S:
            self._write_line(line, now)
        else:
            self._pending = line

    def _write_line(self, line, now):
        sys.stderr.write(line + "\n")
        sys.stderr.flush()
        self._last, self._pending, self._logged_at = line, "", now

    def close(self):
        if self._tty and self._last:
            sys.stderr.write("\n")
            sys.stderr.flush()
        elif self._pending and self._pending != self._last:
            self._write_line(self._pending, time.monotonic())


class _Tqdm:
    def __init__(self, tqdm, description):
        # Thousandths make a meaningless rate: the bar, the times and the job's status only.
        self._bar = tqdm(total=1000, desc=description, leave=True,
                         bar_format="{desc}: {percentage:5.1f}%|{bar}| {elapsed}<{remaining}"
                                    "{postfix}")

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
        return StderrLine(description)
    return _Tqdm(tqdm, description)
