"""A real seepd for the Python tests: started on a free loopback port in a fresh work folder,
stopped with SIGTERM (which must end it cleanly, exit code 0)."""
import os
import shutil
import signal
import subprocess
import time


class SeepdError(Exception):
    pass


class Seepd:
    def __init__(self, seepd, work_dir, extra_args=()):
        self.work_dir = work_dir
        shutil.rmtree(work_dir, ignore_errors=True)
        os.makedirs(work_dir)
        port_file = os.path.join(work_dir, "port")
        self._log_path = os.path.join(work_dir, "seepd.out")
        with open(self._log_path, "w") as log:
            self._process = subprocess.Popen(
                [seepd, "--listen", "127.0.0.1:0", "--data-dir", os.path.join(work_dir, "data"),
                 "--port-file", port_file] + list(extra_args),
                stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)
        self.port = self._wait_for_port(port_file)
        self.address = "127.0.0.1:%d" % self.port

    def _wait_for_port(self, port_file):
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            if self._process.poll() is not None:
                raise SeepdError("seepd exited with %d; see %s" %
                                 (self._process.returncode, self._log_path))
            try:
                with open(port_file) as f:
                    port = int(f.read().strip() or "0")
                if port > 0:
                    return port
            except (OSError, ValueError):
                pass
            time.sleep(0.02)
        self._process.kill()
        raise SeepdError("seepd did not write its port within 30 s")

    def stop(self):
        """SIGTERM, then the exit code must be 0; the work folder is removed when it is."""
        self._process.send_signal(signal.SIGTERM)
        try:
            code = self._process.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self._process.kill()
            raise SeepdError("seepd did not stop within 20 s of SIGTERM") from None
        if code != 0:
            raise SeepdError("seepd exited with %d after SIGTERM; see %s" % (code, self._log_path))
        shutil.rmtree(self.work_dir, ignore_errors=True)
