#!/usr/bin/env python3
"""`twincal history` and `twincal plot --history` end to end: a short session through the
server's stdin, its history checked (`--check`: a replay, bit for bit), exported as CSV (one row
per request, the pending one with empty observation fields), then drawn as PNG and SVG; a
damaged copy refused by `--check`; `serve --listen` on a port in use leaves no database.

    history_and_plot.py TWINCAL
"""
import csv
import json
import os
import shutil
import socket
import sqlite3
import subprocess
import sys
import tempfile


def main():
    twincal = sys.argv[1]
    with tempfile.TemporaryDirectory() as scratch:
        database = os.path.join(scratch, "cell.db")
        server = subprocess.Popen(
            [twincal, "serve", "--db", database, "--case", "analytic", "--dimension", "2",
             "--locators", "all", "--controller", "w=1", "--durability", "normal",
             "--snapshot-every", "5"],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1)
        for t in range(12):
            server.stdin.write(json.dumps({"op": "propose", "assembly": t}) + "\n")
            proposal = json.loads(server.stdout.readline())
            if t < 11:  # the last request stays pending
                server.stdin.write(json.dumps({"op": "observe", "request_id": proposal["request_id"],
                                               "quality": 0.8 + 0.01 * t}) + "\n")
                assert json.loads(server.stdout.readline())["ok"]
        server.stdin.close()  # end of input ends the server
        assert server.wait(timeout=30) == 0

        checked = subprocess.run([twincal, "history", "--db", database, "--check"],
                                 capture_output=True, text=True, check=True)
        assert "12 requests, 11 observations and 2 snapshots replayed bit for bit" in checked.stdout, \
            checked
        assert "the last request awaits its observation" in checked.stdout, checked
        damaged = os.path.join(scratch, "damaged.db")
        shutil.copy(database, damaged)
        with sqlite3.connect(damaged) as db:
            db.execute("UPDATE observations SET quality = 0.5 WHERE request_id = 5")
        refused = subprocess.run([twincal, "history", "--db", damaged, "--check"],
                                 capture_output=True, text=True)
        assert refused.returncode == 1, refused
        assert "request 5: observations.checksum is" in refused.stderr, refused.stderr

        # A port in use: refused before the new session's database exists.
        with socket.socket() as taken:
            taken.bind(("127.0.0.1", 0))
            taken.listen()
            port = taken.getsockname()[1]
            fresh = os.path.join(scratch, "fresh.db")
            busy = subprocess.run([twincal, "serve", "--db", fresh, "--case", "analytic",
                                   "--listen", f"127.0.0.1:{port}"],
                                  capture_output=True, text=True, timeout=60)
            assert busy.returncode != 0 and "cannot listen" in busy.stderr, busy
            assert not os.path.exists(fresh), "a failed --listen left its database behind"

        history = os.path.join(scratch, "cell.csv")
        subprocess.run([twincal, "history", "--db", database, "--out", history], check=True)
        with open(history, encoding="utf-8", newline="") as f:
            rows = list(csv.DictReader(f))
        assert len(rows) == 12, rows
        assert [row["request_id"] for row in rows] == [str(t) for t in range(1, 13)]
        assert float(rows[3]["quality"]) == 0.8 + 0.01 * 3  # bit for bit
        assert rows[0]["sd_A"] != "" and rows[0]["estimate_B"] != ""
        assert rows[11]["quality"] == "" and rows[11]["observed_at"] == "", rows[11]

        figures = os.path.join(scratch, "figures")
        subprocess.run([twincal, "plot", "--history", history, "--out", figures], check=True)
        for extension in ("png", "svg"):
            path = os.path.join(figures, f"cell.{extension}")
            assert os.path.getsize(path) > 1000, path
    print("history: checked; 12 rows (1 pending); cell.png and cell.svg drawn; a damaged copy "
          "refused; a port in use leaves no database")
    return 0


if __name__ == "__main__":
    sys.exit(main())
