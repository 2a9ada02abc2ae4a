#!/usr/bin/env python3
"""docker/ agrees with the real programs (tests/docker/deployment_check.py finds no problem), and the
checker notices each way a broken copy of docker/ disagrees with them (a check that cannot fail proves
nothing).

    docker_config_test.py --repo REPO --bin-dir BUILD/bin"""

import argparse
import shutil
import sys
import tempfile
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "docker"))
import deployment_check  # noqa: E402

ARGS = None

# (file under docker/, text to replace, replacement, words one of the reported problems must contain)
BREAKAGES = [
    ("Dockerfile", "EXPOSE 50051 8080 8081", "EXPOSE 50052 8080 8081", "EXPOSE [8080, 8081, 50052]"),
    ("Dockerfile", "K4REG_GRPC_LISTEN=0.0.0.0:50051", "K4REG_GRPC_LISTEN=0.0.0.0:50052", "EXPOSE [8080, 8081, 50051] but"),
    ("Dockerfile", "    K4REG_HEALTH_LISTEN=0.0.0.0:8081 \\\n", "", "must set K4REG_HEALTH_LISTEN"),
    ("Dockerfile", "K4REG_HEALTH_LISTEN=0.0.0.0:8081", "K4REG_HEALTH_LISTEN=0.0.0.0:8082", "livenessProbe must use the health listener's port 8082"),
    ("Dockerfile", 'ENTRYPOINT ["k4reg-server"]', "ENTRYPOINT k4reg-server", "ENTRYPOINT must be in exec form"),
    ("Dockerfile", 'ENTRYPOINT ["k4reg-server"]', 'ENTRYPOINT ["k4reg-server", "--grpc-port", "1"]', "--grpc-port is not a k4reg-server option"),
    ("Dockerfile", "USER 10001:10001", "USER k4reg", "USER must be a numeric non-root uid"),
    ("Dockerfile", "USER 10001:10001", "USER 0", "USER must be a numeric non-root uid"),
    ("Dockerfile", "libtbb12 zlib1g", "libtbb12 libtbb-dev zlib1g", "libtbb-dev is a -dev package"),
    ("Dockerfile", "libtbb12 zlib1g", "libtbb12 libvtk9.1 zlib1g", "libvtk9.1 pulls in a GUI/VTK stack"),
    ("Dockerfile", "libstdc++6 libtbb12 zlib1g", "libstdc++6 zlib1g", "need libtbb12"),
    ("Dockerfile", "libstdc++6 libtbb12", "libstdc++6 curl libtbb12", "curl is not needed"),
    ("Dockerfile", 'CMD ["k4reg", "health"]', 'CMD ["k4reg", "health", "--server", "127.0.0.1:50051"]', "HEALTHCHECK --server: leave it"),
    ("Dockerfile", 'CMD ["k4reg", "health"]', 'CMD ["k4reg", "health", "--tls"]', "HEALTHCHECK --tls: leave it"),
    ("Dockerfile", 'CMD ["k4reg", "health"]', 'CMD ["k4reg", "health", "--address", "127.0.0.1:8081"]', "--address is not a k4reg health option"),
    ("Dockerfile", "groupadd --system --gid 10001 k4reg \\\n && useradd --system --uid 10001 --gid 10001",
     "useradd --system --uid 10001 --user-group", "the group must be 10001 too"),
    ("Dockerfile", "USER 10001:10001", "USER 10001:999", "the group must be 10001 too"),
    ("Dockerfile", 'CMD ["k4reg", "health"', 'CMD ["k4reg", "status"', "not k4reg health"),
    ("Dockerfile", "K4REG_SPOOL_DIR=/spool", "K4REG_SPOOL_DIRECTORY=/spool", "K4REG_SPOOL_DIRECTORY is not a k4reg-server variable"),
    ("Dockerfile", "mkdir -p /data /spool", "mkdir -p /data", "/spool is used but never created"),
    ("Dockerfile", "chown k4reg:k4reg /spool", "chown k4reg:k4reg /data", "owned by the server's user"),
    ("Dockerfile", "/src/build/bin/k4reg-server /src", "/src/build/bin/k4reg-serverd /src", "k4reg-serverd, which the build does not produce"),
    ("Dockerfile", "ctest --test-dir build -L unit", "ctest --test-dir build", "ctest -L unit"),
    ("Dockerfile", "RUN bash scripts/install-deps.sh --image", "RUN bash scripts/install-deps.sh", "install-deps.sh --image"),
    ("Dockerfile", " -DK4REG_BUILD_BENCH=OFF", "", "-DK4REG_BUILD_BENCH=OFF"),
    ("Dockerfile", " --target k4reg-server k4reg k4reg-unit-tests", "", "must build only --target"),
    ("../scripts/install-deps.sh", "  libgtest-dev libgmock-dev\n)", "  libgtest-dev libgmock-dev libpcl-dev\n)", "pulls in libvtk"),
    ("Dockerfile", "FROM debian:12-slim", "FROM ubuntu:24.04", "not Debian 12"),
    ("Dockerfile", "# k4reg-server image.", "# k4reg-server image (K4REG_THREADS).", "K4REG_THREADS is neither"),
    ("compose.yaml", "read_only: true", "read_only: false", "read-only bind mount"),
    ("compose.yaml", "target: /data", "target: /scans", "must bind-mount the data root"),
    ("compose.yaml", "../tests/data/bunny}", "../tests/data/rabbit}", "does not exist"),
    ("compose.yaml", "stop_grace_period: 40s", "stop_grace_period: 30s", "stop timeout 30 s"),
    ("compose.yaml", '"--concurrency"', '"--concurency"', "--concurency is not a k4reg load option"),
    ("compose.yaml", '"server:50051"', '"server:8080"', "load: --server 'server:8080'"),
    ("compose.yaml", '"bun000.ply"', '"bun999.ply"', "bun999.ply is not in"),
    ("compose.yaml", "condition: service_healthy", "condition: service_started", "service_healthy"),
    ("compose.yaml", "      disable: true\n", "      interval: 10s\n", "disable the image's HEALTHCHECK"),
    ("compose.yaml", '      K4REG_WORKERS: "2"\n', "", "must set K4REG_WORKERS"),
    ("compose.yaml", "K4REG_SERVER_ID:", "K4REG_SERVERID:", "K4REG_SERVERID is not a k4reg-server variable"),
    ("compose.yaml", '"127.0.0.1:8080:8080"', '"127.0.0.1:8080:8082"', "publishes [8082, 50051]"),
    ("compose.yaml", "dockerfile: docker/Dockerfile", "dockerfile: Dockerfile", "does not build docker/Dockerfile"),
    ("k8s/deployment.yaml", "service: readiness", "service: ready", "readinessProbe service 'ready'"),
    ("k8s/deployment.yaml", "port: 8081\n              service: liveness", "port: 50051\n              service: liveness",
     "livenessProbe must use the health listener's port 8081"),
    ("k8s/deployment.yaml", "port: 8081\n              service: readiness", "port: 50051\n              service: readiness",
     "readinessProbe must use the health listener's port 8081"),
    ("k8s/deployment.yaml", "terminationGracePeriodSeconds: 90", "terminationGracePeriodSeconds: 60", "stop timeout 60 s"),
    ("k8s/deployment.yaml", '            - name: K4REG_MAX_CONNECTION_AGE_S\n              value: "300"\n', "", "K4REG_MAX_CONNECTION_AGE_S must be set"),
    ("k8s/deployment.yaml", "K4REG_QUEUE_SIZE", "K4REG_QUEUE_LENGTH", "K4REG_QUEUE_LENGTH is not a k4reg-server variable"),
    ("k8s/deployment.yaml", 'K4REG_WORKERS\n              value: "2"', 'K4REG_WORKERS\n              value: "4"', "= 4 threads on 2 cores"),
    ("k8s/deployment.yaml", 'K4REG_MEMORY_BUDGET_MB\n              value: "3072"', 'K4REG_MEMORY_BUDGET_MB\n              value: "5000"',
     "memory limit 5Gi < budget 5000"),
    ("k8s/deployment.yaml", 'K4REG_MAX_PAIR_MB\n              value: "128"', 'K4REG_MAX_PAIR_MB\n              value: "512"',
     "their kept scans 2560"),
    ("k8s/deployment.yaml", "K4REG_PEERS", "K4REG_PEER", "K4REG_PEER is not a k4reg-server variable"),
    ("k8s/deployment.yaml", "containerPort: 8080", "containerPort: 8081", "container ports"),
    ("k8s/deployment.yaml", 'prometheus.io/port: "8080"', 'prometheus.io/port: "9090"', "prometheus.io/port 9090 is not the HTTP port"),
    ("k8s/deployment.yaml", "runAsNonRoot: true", "runAsNonRoot: false", "runAsNonRoot must be true"),
    ("k8s/deployment.yaml", "runAsUser: 10001", "runAsUser: 1000", "runAsUser differs"),
    ("k8s/deployment.yaml", "mountPath: /spool", "mountPath: /tmp", "needs a writable volume"),
    ("k8s/deployment.yaml", "image: k4reg:0.1.0", "image: k4reg:latest", "image must be k4reg:0.1.0"),
    ("k8s/deployment.yaml", "  # No replicas field", "  replicas: 3\n  # No replicas field", "no replicas field"),
    ("k8s/service.yaml", "targetPort: http", "targetPort: metrics", "targetPort 'metrics' is not a container port"),
    ("k8s/service.yaml", "app.kubernetes.io/component: server", "app.kubernetes.io/component: api", "selector does not match"),
    ("k8s/service-headless.yaml", "  clusterIP: None\n", "", "needs a headless Service"),
    ("k8s/service-headless.yaml", "port: 50051", "port: 80", "expose the gRPC port 50051 as itself"),
    ("k8s/hpa.yaml", "    name: k4reg\n  minReplicas", "    name: k4reg-server\n  minReplicas", "scaleTargetRef"),
    ("k8s/hpa.yaml", "name: cpu", "name: memory", "must scale on CPU"),
    ("k8s/pdb.yaml", "maxUnavailable: 1", "minAvailable: 2", "block every voluntary disruption"),
    ("k8s/kustomization.yaml", "  - pdb.yaml\n", "", "resources"),
    ("k8s/deployment.yaml", "automountServiceAccountToken: false", "automountServiceAccountToken: true",
     "automountServiceAccountToken must be false"),
    ("k8s/deployment.yaml", "K4REG_AUTH_TOKEN\n              valueFrom:\n                secretKeyRef:\n                  name: k4reg-token\n"
     "                  key: auth-token", "K4REG_AUTH_TOKEN\n              value: s3cret", "K4REG_AUTH_TOKEN must come from a Secret"),
    ("k8s/deployment.yaml", "              ephemeral-storage: 17Gi\n", "", "needs ephemeral-storage requests and limits"),
    ("k8s/deployment.yaml", "sizeLimit: 16Gi", "sizeLimit: 32Gi", "below the spool volume's sizeLimit"),
    ("k8s/networkpolicy.yaml", "kind: NetworkPolicy", "kind: NetworkPolicyList", "needs a NetworkPolicy"),
    ("k8s/networkpolicy.yaml", "        - port: health", "        - port: grpc", "the grpc port must be reachable from the allowed"),
    ("k8s/networkpolicy.yaml", "        - podSelector:\n", "        - namespaceSelector: {}\n          podSelector:\n",
     "the replicas must reach each other's gRPC port"),
    ("k8s/pdb.yaml", "maxUnavailable: 1", "maxUnavailable: [1", "cannot read the files"),
]


def mirror(repo, target):
    """`target` as a stand-in for the repository: its own copies of docker/ and scripts/, links to everything else."""
    copied = ("docker", "scripts")
    for entry in repo.iterdir():
        if entry.name not in copied:
            (target / entry.name).symlink_to(entry)
    for name in copied:
        shutil.copytree(repo / name, target / name)
    return target


class DeploymentCheck(unittest.TestCase):
    def test_docker_folder_agrees_with_the_programs(self):
        self.assertEqual(deployment_check.check(ARGS.repo, ARGS.bin_dir), [])

    def test_a_faithful_copy_passes(self):
        with tempfile.TemporaryDirectory() as temp:
            self.assertEqual(deployment_check.check(mirror(ARGS.repo, Path(temp)), ARGS.bin_dir), [])

    def test_every_breakage_is_reported(self):
        for file, old, new, expected in BREAKAGES:
            with self.subTest(file=file, change=new), tempfile.TemporaryDirectory() as temp:
                repo = mirror(ARGS.repo, Path(temp))
                path = repo / "docker" / file
                text = path.read_text()
                self.assertIn(old, text, "the breakage no longer applies: update BREAKAGES")
                path.write_text(text.replace(old, new, 1))
                problems = deployment_check.check(repo, ARGS.bin_dir)
                self.assertTrue(any(expected in p for p in problems), f"expected {expected!r} among {problems}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--repo", required=True, type=Path)
    parser.add_argument("--bin-dir", required=True, type=Path)
    ARGS, rest = parser.parse_known_args()
    ARGS.repo = ARGS.repo.resolve()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
