#!/usr/bin/env python3
"""The container's command line, run without a container: ENTRYPOINT + CMD + ENV of docker/Dockerfile
(and the server environment compose.yaml and k8s/deployment.yaml add), with the binaries from the build
and container paths mapped to host folders: the data root to tests/data/bunny, the spool and the WORKDIR
to temporary folders, host files (test certificates) as they are. The one other change: listen ports
become 0 (ephemeral, so tests can run in parallel); the host part stays, and the HEALTHCHECK runs with the
container's environment, K4REG_HEALTH_LISTEN naming the bound port.

Checks the HEALTHCHECK command and HTTP /healthz and /readyz, a registration of the bunny pair, and the
SIGTERM drain: a job running when the signal arrives completes within the drain grace, readiness turns
NOT_SERVING (gRPC) and 503 (HTTP), exit code 0; and the HEALTHCHECK with TLS on and off.

    docker_entrypoint_test.py --repo REPO --bin-dir BUILD/bin"""

import argparse
import json
import math
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
import unittest
import urllib.error
import urllib.request
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "docker"))
import deployment_check  # noqa: E402
import dockerfile  # noqa: E402

ARGS = None
# The bunny pair in about a second (as tests/integration/test_support.cpp bunny_params) ...
BUNNY = ["bun045.ply", "bun000.ply", "--ref", "--min-scale", "0.001", "--overlap", "0.9"]
# ... and a job of a few seconds, well within the drain grace: many 4PCS bases (~1.6 ms each, one core).
SLOW_BASES = "1500"
LISTEN_VARIABLES = ("K4REG_GRPC_LISTEN", "K4REG_HTTP_LISTEN", "K4REG_HEALTH_LISTEN")


def self_signed_certificate(folder):
    """(cert, key) for localhost and 127.0.0.1, as docs/deployment.md's TLS walk-through makes one."""
    cert, key = Path(folder) / "cert.pem", Path(folder) / "key.pem"
    subprocess.run(["openssl", "req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes",
                    "-days", "1", "-subj", "/CN=localhost", "-addext", "subjectAltName=DNS:localhost,IP:127.0.0.1",
                    "-keyout", str(key), "-out", str(cert)], check=True, capture_output=True)
    return cert, key


def read_log(path):
    """The server's JSON log lines."""
    lines = []
    for line in Path(path).read_text().splitlines():
        try:
            lines.append(json.loads(line))
        except json.JSONDecodeError:
            pass
    return lines


def wait_for(condition, timeout_s, what):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        value = condition()
        if value:
            return value
        time.sleep(0.02)
    raise AssertionError(f"timed out waiting for {what}")


def ephemeral(address):
    """host:port -> host:0."""
    return address.rsplit(":", 1)[0] + ":0"


class ContainerRun:
    """k4reg-server started as the image starts it, with `overrides` added to its environment."""

    def __init__(self, d, overrides, work):
        self.d, self.work = d, Path(work)
        runtime = d.runtime
        self.binaries = {name: ARGS.bin_dir / name for name in dockerfile.copied_from(runtime, d.stages[0].name)}
        values = {**{k: v for k, v in dockerfile.env(runtime).items() if k.startswith("K4REG_")}, **overrides}
        self.data_roots = [r for r in values.get("K4REG_DATA_ROOT", "").split(":") if r]
        self.container_values = values
        env = {k: v for k, v in os.environ.items() if not k.startswith("K4REG_")}
        for name, value in values.items():
            if name in LISTEN_VARIABLES and value:
                value = ephemeral(value)
            elif name == "K4REG_DATA_ROOT":
                value = ":".join(str(self.host_path(r)) for r in self.data_roots)
            elif value.startswith("/") and not Path(value).is_file():
                value = str(self.host_path(value))
            elif value.startswith("<field:"):
                value = "pod-" + value[len("<field:") : -1].replace(".", "-")
            env[name] = value
        self.env = env
        entrypoint = dockerfile.exec_form(runtime.last("ENTRYPOINT").arguments)
        cmd = runtime.last("CMD")
        argv = entrypoint + (dockerfile.exec_form(cmd.arguments) if cmd else [])
        self.argv = [str(self.binaries[argv[0]])] + argv[1:]
        workdir = runtime.last("WORKDIR")
        self.cwd = self.host_path(workdir.arguments) if workdir else self.work
        self.log_path = self.work / "server.log"
        with open(self.log_path, "wb") as log:
            self.process = subprocess.Popen(self.argv, env=self.env, cwd=self.cwd, stderr=log, stdout=subprocess.DEVNULL)
        serving = wait_for(lambda: self.log("serving") or self.process.poll() is not None, 30, "the server to start")
        assert self.process.poll() is None, f"the server exited at start-up: {self.log_path.read_text()}"
        self.grpc_port = serving[0]["grpc_port"]
        self.http_port = serving[0].get("http_port")
        self.health_port = serving[0].get("health_port")

    def host_path(self, container_path):
        """Data roots are the bunny scans; any other container folder becomes a fresh folder under `work`."""
        if container_path in self.data_roots:
            return ARGS.repo / "tests/data/bunny"
        path = self.work / container_path.strip("/").replace("/", "_")
        path.mkdir(exist_ok=True)
        return path

    def log(self, msg):
        return [line for line in read_log(self.log_path) if line.get("msg") == msg]

    def healthcheck(self, **env):
        """The image's HEALTHCHECK command in the container's environment (as Docker runs it), the health
        listener at its bound port, plus `env`."""
        command = dockerfile.healthcheck(self.d.runtime)[1]
        environment = dict(self.env, **env)
        if self.health_port:
            environment["K4REG_HEALTH_LISTEN"] = re.sub(r":\d+$", f":{self.health_port}", environment["K4REG_HEALTH_LISTEN"])
        argv = [str(self.binaries[command[0]])] + command[1:]
        return subprocess.run(argv, capture_output=True, text=True, timeout=30, env=environment)

    def http_get(self, path, port=None):
        """(status code, body) of GET http://127.0.0.1:<port, default the bound HTTP port><path>."""
        direct = urllib.request.build_opener(urllib.request.ProxyHandler({}))  # never an http_proxy for loopback
        try:
            with direct.open(f"http://127.0.0.1:{port or self.http_port}{path}", timeout=10) as reply:
                return reply.status, reply.read().decode()
        except urllib.error.HTTPError as error:
            return error.code, error.read().decode()

    def client(self, *arguments, **popen):
        """k4reg with --server pointing at this server."""
        argv = [str(self.binaries["k4reg"]), *arguments, "--server", f"127.0.0.1:{self.grpc_port}"]
        return subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **popen)

    def stop(self):
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
        return self.process.wait(timeout=60)

    def kill(self):
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()


def same_value(logged, text):
    if isinstance(logged, bool):  # a flag: the environment says true/false
        return logged == (text.lower() in ("true", "1", "yes", "on"))
    try:
        return float(logged) == float(text)
    except (TypeError, ValueError):
        return str(logged) == text


def bunny_truth():
    """T_target_source of bun045 -> bun000 from tests/data/bunny/gt_pairs.log (row-major, 16 numbers)."""
    lines = [l for l in (ARGS.repo / "tests/data/bunny/gt_pairs.log").read_text().splitlines() if not l.startswith("#")]
    for i, line in enumerate(lines):
        if line.split()[:2] == ["bun045.ply", "bun000.ply"]:
            return [float(v) for row in lines[i + 1 : i + 5] for v in row.split()]
    raise AssertionError("no ground truth for bun045 -> bun000")


def pose_error(estimate, truth):
    """(rotation angle in degrees, translation distance) between two row-major 4x4 rigid transforms."""
    trace = sum(estimate[4 * k + i] * truth[4 * k + i] for i in range(3) for k in range(3))  # trace(Re^T Rt)
    angle = math.degrees(math.acos(max(-1.0, min(1.0, (trace - 1) / 2))))
    return angle, math.dist([estimate[3], estimate[7], estimate[11]], [truth[3], truth[7], truth[11]])


class EntrypointTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.d = deployment_check.load(ARGS.repo, ARGS.bin_dir)

    def run_container(self, overrides):
        work = tempfile.TemporaryDirectory()
        self.addCleanup(work.cleanup)
        server = ContainerRun(self.d, overrides, work.name)
        self.addCleanup(server.kill)
        return server

    def test_image_serves_registers_and_drains(self):
        server = self.run_container({})
        health = server.healthcheck()
        self.assertEqual(health.returncode, 0, health.stdout + health.stderr)
        self.assertIn("readiness: SERVING", health.stdout)
        self.assertIsNotNone(server.http_port, "the image sets K4REG_HTTP_LISTEN; the server must serve HTTP")
        status, body = server.http_get("/healthz")
        self.assertEqual((status, json.loads(body)), (200, {"status": "SERVING"}))
        self.assertEqual(server.http_get("/readyz")[0], 200)

        # A registration of files under the data root, as the compose load service sends them.
        client = server.client("register", *BUNNY, "--json")
        out, err = client.communicate(timeout=120)
        self.assertEqual(client.returncode, 0, err)
        rotation_deg, translation_m = pose_error(json.loads(out)["transform"], bunny_truth())
        self.assertLess(rotation_deg, 1.0)
        self.assertLess(translation_m, 0.002)

        # SIGTERM while a job runs: the job is within the drain grace, so it completes and is answered.
        slow = server.client("register", *BUNNY, "--bases", SLOW_BASES, "--json")
        wait_for(lambda: "matching started" in slow.stderr.readline(), 60, "the job to reach its 4PCS stage")
        server.process.send_signal(signal.SIGTERM)
        draining = wait_for(lambda: server.log("draining"), 10, "the drain to start")[0]
        self.assertEqual(draining["running"], 1, "the job was not running when SIGTERM arrived")
        health = server.healthcheck()
        self.assertEqual(health.returncode, 1, "the HEALTHCHECK must fail while draining")
        self.assertIn("readiness: NOT_SERVING", health.stdout)
        self.assertEqual(server.http_get("/readyz")[0], 503)
        self.assertEqual(server.http_get("/healthz")[0], 200)
        out, err = slow.communicate(timeout=120)
        self.assertEqual(slow.returncode, 0, err)
        self.assertIn("transform", json.loads(out))
        self.assertEqual(server.process.wait(timeout=60), 0, server.log_path.read_text())
        self.assertEqual(server.log("drain grace period over, cancelling jobs"), [])
        self.assertTrue(server.log("stopped"))
        spool = server.host_path(server.container_values["K4REG_SPOOL_DIR"])
        self.assertEqual(list(spool.iterdir()), [], "the spool folder must be empty after exit")

    def test_healthcheck_with_tls_on_and_off(self):
        folder = tempfile.TemporaryDirectory()
        self.addCleanup(folder.cleanup)
        cert, key = self_signed_certificate(folder.name)
        tls = {"K4REG_TLS_CERT": str(cert), "K4REG_TLS_KEY": str(key)}
        for name, overrides in (("plaintext", {}), ("tls", tls), ("mutual tls", {**tls, "K4REG_TLS_CLIENT_CA": str(cert)})):
            with self.subTest(configuration=name):
                server = self.run_container(overrides)
                health = server.healthcheck()
                self.assertEqual(health.returncode, 0, health.stdout + health.stderr)
                self.assertIn("readiness: SERVING", health.stdout)
                self.assertEqual(server.http_get("/readyz", port=server.health_port)[0], 200)
                plaintext = server.client("health")
                plaintext.communicate(timeout=30)
                self.assertEqual(plaintext.returncode, 1 if overrides else 0, "plaintext gRPC to the API port")
                self.assertEqual(server.stop(), 0, server.log_path.read_text())
        # Without the health listener the check follows K4REG_SERVER, K4REG_TLS and K4REG_CA_CERT instead.
        server = self.run_container({**tls, "K4REG_HEALTH_LISTEN": ""})
        self.assertIsNone(server.health_port)
        health = server.healthcheck(K4REG_SERVER=f"localhost:{server.grpc_port}", K4REG_TLS="1", K4REG_CA_CERT=str(cert))
        self.assertEqual(health.returncode, 0, health.stdout + health.stderr)
        self.assertEqual(server.healthcheck(K4REG_SERVER=f"localhost:{server.grpc_port}").returncode, 1)

    def test_compose_and_kubernetes_settings_start_and_stop(self):
        for name, overrides in (("compose", deployment_check.compose_env(self.d)), ("k8s", deployment_check.k8s_env(self.d))):
            with self.subTest(configuration=name):
                server = self.run_container(overrides)
                health = server.healthcheck()
                self.assertEqual(health.returncode, 0, health.stdout + health.stderr)
                self.assertEqual(server.http_get("/healthz")[0], 200)
                scrape = deployment_check.k8s_scrape_path(self.d) if name == "k8s" else None
                if scrape:
                    status, body = server.http_get(scrape)
                    self.assertEqual(status, 200, f"Prometheus would scrape {scrape}")
                    self.assertIn("k4reg_build_info", body)
                # The start-up log line names each setting after its flag (--max-connection-age-s: max_connection_age_s).
                config = server.log("starting")[0]["config"]
                for variable, value in overrides.items():
                    if not variable.startswith("K4REG_"):
                        continue  # the pod's own (POD_NAMESPACE, for K4REG_PEERS)
                    option = next(o for o in self.d.server_options.values() if o.env == variable)
                    key = option.name[2:].replace("-", "_")
                    if key in config and not value.startswith(("<", "/")):
                        self.assertTrue(same_value(config[key], value), f"{variable}={value} reached the server as {config[key]}")
                self.assertEqual(server.stop(), 0, server.log_path.read_text())


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--repo", required=True, type=Path)
    parser.add_argument("--bin-dir", required=True, type=Path)
    ARGS, rest = parser.parse_known_args()
    ARGS.repo, ARGS.bin_dir = ARGS.repo.resolve(), ARGS.bin_dir.resolve()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
