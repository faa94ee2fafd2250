#!/usr/bin/env python3
"""A simulated welding cell driving `twincal serve` (docs/serve.md), standard library only.

    python3 serve_client.py /path/to/twincal [--tcp] [--assemblies N] [--db FILE]

Starts `twincal serve` on the analytic twin with every locator drifting (d = 3) and the active
controller, then per assembly: `propose` (which assembly comes next) → the locator adjustment u_t
→ the cell welds it → `observe` (the measured quality z_t). The cell's true locator offset δu*
drifts and is never shown to the controller; the simulated cell measures by asking the twin
(`predict`) what a cell with that offset would measure. It prints the relative residual
(z_t − z*)/z* against the baseline's (u0(x_t), an uncalibrated twin) and fails (exit 1) unless
the controller halves it over the second half of the run.

`ServeClient` is the reusable part: one request, one reply, over the server's stdin/stdout or a
TCP connection.
"""
import argparse
import json
import math
import os
import socket
import subprocess
import sys
import tempfile


class ServeError(RuntimeError):
    """The server answered {"ok": false, "error": {"field", "message"}}."""

    def __init__(self, reply):
        super().__init__(reply["error"]["message"])
        self.field = reply["error"]["field"]


class ServeClient:
    """`twincal serve` as a child process; requests over its stdin/stdout or over TCP."""

    def __init__(self, twincal, arguments, tcp=False):
        command = [twincal, "serve", *arguments]
        if tcp:
            command += ["--listen", "127.0.0.1:0"]
        self.process = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                        stderr=subprocess.PIPE, text=True, bufsize=1)
        self.socket = None
        if tcp:
            # "twincal serve: listening on 127.0.0.1:PORT" once it accepts connections.
            line = self.process.stderr.readline()
            if "listening on" not in line:
                raise RuntimeError(f"twincal serve did not start: {line}{self.process.stderr.read()}")
            port = int(line.rsplit(":", 1)[1])
            self.socket = socket.create_connection(("127.0.0.1", port))
            self.reader = self.socket.makefile("r", encoding="utf-8", newline="\n")
            self.writer = self.socket.makefile("w", encoding="utf-8", newline="\n")
        else:
            self.reader, self.writer = self.process.stdout, self.process.stdin

    def send(self, request):
        """Writes one request line (without waiting for the reply)."""
        self.writer.write(json.dumps(request) + "\n")
        self.writer.flush()

    def receive(self):
        line = self.reader.readline()
        if not line:
            raise EOFError("twincal serve closed the connection: "
                           + (self.process.stderr.read() if self.process.poll() is not None else ""))
        reply = json.loads(line)
        if not reply["ok"]:
            raise ServeError(reply)
        return reply

    def call(self, op, **fields):
        self.send({"op": op, **fields})
        return self.receive()

    def close(self):
        """Asks the server to shut down and waits for it."""
        try:
            self.call("shutdown")
        finally:
            if self.socket is not None:
                self.socket.close()
            self.process.stdin.close()
            self.process.wait(timeout=30)
            self.process.stdout.close()
            self.process.stderr.close()

    def kill(self):
        """kill -9: what a power cut or a crash does to the server."""
        self.process.kill()
        self.process.wait()
        for stream in (self.process.stdin, self.process.stdout, self.process.stderr):
            stream.close()
        if self.socket is not None:
            self.socket.close()


def hidden_offset(t, d):
    """The cell's true locator offset δu*_t: a slow drift the controller never sees."""
    return [0.2 * math.sin(0.03 * t + 1.3 * i) for i in range(d)]


def weld(client, assembly, control, t):
    """The quality the cell measures: the twin at u_t − δu*_t (the plant of eq. 5b)."""
    offset = hidden_offset(t, len(control))
    shifted = [u - e for u, e in zip(control, offset)]
    return client.call("predict", assembly=assembly, control=shifted)["quality"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("twincal", help="path of the twincal program")
    parser.add_argument("--tcp", action="store_true", help="talk over TCP, not stdin/stdout")
    parser.add_argument("--assemblies", type=int, default=60)
    parser.add_argument("--db", help="history database (default: a temporary file)")
    options = parser.parse_args()

    with tempfile.TemporaryDirectory() as scratch:
        database = options.db or os.path.join(scratch, "cell.db")
        client = ServeClient(options.twincal,
                             ["--db", database, "--case", "analytic", "--dimension", "3",
                              "--locators", "all", "--controller", "active"], tcp=options.tcp)
        residuals, baseline_residuals = [], []
        try:
            for t in range(options.assemblies):
                assembly = (37 * t) % 100  # the production order of the cell
                proposal = client.call("propose", assembly=assembly)
                quality = weld(client, assembly, proposal["control"], t)
                observed = client.call("observe", request_id=proposal["request_id"],
                                       quality=quality)
                # The paper's measure, (z − z*)/z*, and the same for the baseline u0(x_t)
                # (individualized control with an uncalibrated twin) at the same offset.
                best = proposal["report"]["optimal_quality"]
                baseline = weld(client, assembly, proposal["report"]["optimum"], t)
                residuals.append((quality - best) / best)
                baseline_residuals.append((baseline - best) / best)
                if t % 10 == 0 or t == options.assemblies - 1:
                    error = math.dist(observed["estimate"], hidden_offset(t, 3))
                    print(f"assembly {t:3d}: relative residual {residuals[-1]:.5f} "
                          f"(baseline {baseline_residuals[-1]:.5f}), "
                          f"|estimate - offset| = {error:.4f}")
            state = client.call("state")
        finally:
            client.close()
        print(f"{state['observed']} assemblies observed; history in {database}")
        # After a burn-in, the calibrated controller must halve the baseline's residual.
        half = options.assemblies // 2
        mean = sum(residuals[half:]) / (options.assemblies - half)
        baseline_mean = sum(baseline_residuals[half:]) / (options.assemblies - half)
        print(f"mean relative residual over the second half: {mean:.5f} "
              f"(baseline {baseline_mean:.5f})")
        if not mean < 0.5 * baseline_mean:
            print("FAILED: the controller did not halve the baseline's residual", file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
