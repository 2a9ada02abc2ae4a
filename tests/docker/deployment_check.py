#!/usr/bin/env python3
"""Checks docker/ (Dockerfile, compose.yaml, k8s/) against the real programs: option and variable names,
defaults and ports from `k4reg-server --help`, client flags from `k4reg health|load --help`, probe names
from server/observability/health.h, runtime packages from `ldd` + `dpkg -S` of the built binaries.

    deployment_check.py --repo . --bin-dir build/bin      # prints the problems, exit code 1 if any

Used by tests/integration/docker_config_test.py (which also proves it catches broken copies) and, for the
configurations the container files define, by tests/integration/docker_entrypoint_test.py."""

import argparse
import functools
import math
import os
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))
import cli_help  # noqa: E402
import dockerfile  # noqa: E402

# After the drain grace the server waits up to 10 s for cancelled jobs and 2 s for gRPC to finish
# (server/main.cpp); a stop timeout must cover all of it.
SHUTDOWN_AFTER_GRACE_S = 12
# Memory of the server process itself beyond its job budget (measured: 18 MB idle), with gRPC buffers.
PROCESS_OVERHEAD_MIB = 256
PATH_DIRS = ("/usr/local/bin/", "/usr/bin/", "/bin/")
LOOPBACK_HOSTS = ("127.0.0.1", "localhost", "[::1]")
BUILD_TOOLS = re.compile(r"^(build-essential|gcc|g\+\+|cpp|clang|cmake|make|ninja-build)(-\d+)?$")
VISUALIZATION = re.compile(r"vtk|pcl-visualization|qt")
# What the image's build stage must not install, directly or through dependencies: PCL and its VTK/Qt/MPI
# stack, a JDK, clang/LLVM, and the tools only CI or the benchmarks use.
HEAVY_BUILD_PACKAGES = re.compile(r"^(libpcl|libvtk|libqt|qt\d|openjdk|default-jdk|default-jre|clang|libclang|llvm|"
                                  r"libopenmpi|openmpi|mpi-default|prometheus|gnuplot|docker-compose|libbenchmark)")
# The flags a HEALTHCHECK must leave to the environment (K4REG_HEALTH_LISTEN, or K4REG_SERVER / _TLS / _CA_CERT).
HEALTHCHECK_FIXED_FLAGS = ("--server", "--tls", "--ca-cert")


@dataclass
class Deployment:
    """Everything the checks compare, read once."""

    repo: Path
    docker: Path
    bin_dir: Path
    server_options: dict  # "--flag" -> cli_help.Option
    client_options: dict  # "health"/"load" -> {"--flag": Option}
    health_names: dict  # "kLivenessService" -> "liveness", ...
    version: str
    stages: list
    compose: dict
    manifests: list  # (file name, document)

    @property
    def runtime(self):
        return self.stages[-1]

    def env_names(self):
        return {o.env for o in self.server_options.values() if o.env}

    def client_env_names(self):
        return {o.env for options in self.client_options.values() for o in options.values() if o.env}

    def kind(self, kind):
        return [(name, doc) for name, doc in self.manifests if doc.get("kind") == kind]

    def deployment(self):
        found = self.kind("Deployment")
        return found[0] if found else (None, None)


# Cached: the config test checks many altered copies of docker/ against the same binaries.
@functools.lru_cache(maxsize=None)
def program_options(*command):
    return cli_help.program_options(command)


def load(repo, bin_dir, docker_dir=None):
    repo, bin_dir = Path(repo), Path(bin_dir)
    docker = Path(docker_dir) if docker_dir else repo / "docker"
    health_h = (repo / "server/observability/health.h").read_text()
    version = re.search(r"project\(k4reg VERSION (\S+)", (repo / "CMakeLists.txt").read_text())
    manifests = []
    for path in sorted((docker / "k8s").glob("*.yaml")):
        if path.name != "kustomization.yaml":
            manifests += [(path.name, doc) for doc in yaml.safe_load_all(path.read_text()) if doc]
    return Deployment(
        repo=repo,
        docker=docker,
        bin_dir=bin_dir,
        server_options=program_options(bin_dir / "k4reg-server"),
        client_options={c: program_options(bin_dir / "k4reg", c) for c in ("health", "load")},
        health_names=dict(re.findall(r'(k\w+Service) = "([^"]*)"', health_h)),
        version=version.group(1) if version else "",
        stages=dockerfile.parse((docker / "Dockerfile").read_text()),
        compose=yaml.safe_load((docker / "compose.yaml").read_text()),
        manifests=manifests,
    )


# ---- the server's effective settings in each configuration -------------------------------------------


def image_env(d):
    return dockerfile.env(d.runtime)


def compose_env(d):
    return {str(k): str(v) for k, v in (d.compose["services"]["server"].get("environment") or {}).items()}


def k8s_container(d):
    _, deployment = d.deployment()
    return deployment["spec"]["template"]["spec"]["containers"][0] if deployment else {}


def k8s_env(d):
    """Literal values, "<field:PATH>" for values Kubernetes fills in (valueFrom) and "<secret:NAME/KEY>" for Secrets."""
    env = {}
    for entry in k8s_container(d).get("env", []):
        source = entry.get("valueFrom", {})
        secret = source.get("secretKeyRef")
        env[entry["name"]] = (str(entry["value"]) if "value" in entry else
                              f"<secret:{secret.get('name')}/{secret.get('key')}>" if secret else
                              f"<field:{source.get('fieldRef', {}).get('fieldPath')}>")
    return env


def k8s_scrape_path(d):
    """The path the pod annotations tell Prometheus to scrape, or None."""
    _, deployment = d.deployment()
    annotations = deployment["spec"]["template"]["metadata"].get("annotations", {}) if deployment else {}
    return annotations.get("prometheus.io/path", "/metrics") if annotations.get("prometheus.io/scrape") == "true" else None


def settings(d, overrides):
    """Variable -> value the server ends up with: --help defaults, then the image's ENV, then `overrides`."""
    values = {o.env: o.default for o in d.server_options.values() if o.env}
    values.update({k: v for k, v in image_env(d).items() if k.startswith("K4REG_")})
    values.update(overrides)
    return values


def listen_port(address):
    return int(address.rsplit(":", 1)[1]) if address and ":" in address else None


def served_ports(values):
    ports = {"grpc": listen_port(values.get("K4REG_GRPC_LISTEN", ""))}
    if values.get("K4REG_HTTP_LISTEN"):
        ports["http"] = listen_port(values["K4REG_HTTP_LISTEN"])
    if values.get("K4REG_HEALTH_LISTEN"):
        ports["health"] = listen_port(values["K4REG_HEALTH_LISTEN"])
    return ports


def image_build_packages(repo):
    """IMAGE_PACKAGES of scripts/install-deps.sh: what `install-deps.sh --image` installs."""
    text = (Path(repo) / "scripts/install-deps.sh").read_text()
    block = re.search(r"^IMAGE_PACKAGES=\((.*?)^\)", text, re.S | re.M)
    if not block:
        raise ValueError("scripts/install-deps.sh has no IMAGE_PACKAGES=( ... ) list")
    return [w for line in block.group(1).splitlines() for w in line.split("#")[0].split()]


@functools.lru_cache(maxsize=None)
def apt_closure(packages):
    """The packages `packages` pull in (Depends and PreDepends, no Recommends: install-deps.sh passes
    --no-install-recommends), from apt's package lists; None without apt-cache."""
    try:
        done = subprocess.run(["apt-cache", "depends", "--recurse", "--no-recommends", "--no-suggests", "--no-conflicts",
                               "--no-breaks", "--no-replaces", "--no-enhances", *packages],
                              capture_output=True, text=True, timeout=120)
    except FileNotFoundError:
        return None
    return {line.strip() for line in done.stdout.splitlines() if not line.startswith(" ") and not line.startswith("<")}


# ---- the checks ------------------------------------------------------------------------------------------


class Problems(list):
    def expect(self, condition, where, message):
        if not condition:
            self.append(f"{where}: {message}")
        return condition


def check_env_names(d, problems, where, names):
    known = d.env_names()
    for name in names:
        if name.startswith("K4REG_"):
            problems.expect(name in known, where, f"{name} is not a k4reg-server variable (see k4reg-server --help)")


def check_mentioned_variables(d, problems):
    """Every K4REG_* written anywhere in docker/ names a real server or client variable."""
    known = d.env_names() | d.client_env_names()
    for path in sorted(p for p in d.docker.rglob("*") if p.is_file()):
        for name in sorted(set(re.findall(r"\bK4REG_[A-Z0-9_]+", path.read_text(errors="replace")))):
            problems.expect(name in known, path.relative_to(d.docker), f"{name} is neither a server nor a client variable")


@functools.lru_cache(maxsize=None)
def binary_packages(paths):
    """Debian packages of the shared libraries `ldd` lists for the binaries."""
    libraries = set()
    for path in paths:
        done = subprocess.run(["ldd", str(path)], capture_output=True, text=True, check=True)
        libraries |= set(re.findall(r"=> (/\S+)", done.stdout))
    owners = {}  # dpkg knows a file under one name: as linked (/lib/...) or resolved (/usr/lib/...)
    for names in ({lib: lib for lib in libraries}, {os.path.realpath(lib): lib for lib in libraries}):
        done = subprocess.run(["dpkg", "-S", *names], capture_output=True, text=True)  # one call: dpkg -S is slow
        for line in done.stdout.splitlines():
            package, _, path = line.partition(": ")
            if path in names:
                owners.setdefault(names[path], package.split(":")[0])
    return set(owners.values()) | {f"<no package owns {lib}>" for lib in libraries - owners.keys()}


def shell_commands(stage, program):
    """Argument lists of the simple commands running `program` in the stage's RUN lines."""
    commands = []
    for instruction in stage.all("RUN"):
        words = shlex.split(instruction.arguments)
        command = []
        for word in words + ["&&"]:
            if word not in ("&&", "||", ";", "|"):
                command.append(word)
                continue
            while command and re.match(r"^\w+=", command[0]):  # VAR=value prefixes
                command.pop(0)
            if command and command[0] == program:
                commands.append(command[1:])
            command = []
    return commands


def apt_installed(stage):
    """Packages named after `apt-get install` in the stage's RUN lines."""
    return [package for args in shell_commands(stage, "apt-get") if "install" in args
            for package in args[args.index("install") + 1 :] if not package.startswith("-")]


def check_dockerfile(d, problems):
    where = "Dockerfile"
    stages, runtime = d.stages, d.runtime
    problems.expect(len(stages) >= 2, where, "needs a build stage and a runtime stage")
    for stage in stages:
        problems.expect(re.match(r"debian:(12|bookworm)(\b|-)", stage.image), where, f"FROM {stage.image}: not Debian 12")
    build = stages[0]
    build_runs = " ".join(i.arguments for i in build.all("RUN"))
    problems.expect(any(args[:2] == ["scripts/install-deps.sh", "--image"] for args in shell_commands(build, "bash")),
                    where, "the build stage must install with scripts/install-deps.sh --image")
    problems.expect("-DCMAKE_BUILD_TYPE=Release" in build_runs, where, "the build stage must configure Release")
    problems.expect("-DK4REG_BUILD_BENCH=OFF" in build_runs, where, "the build stage must configure -DK4REG_BUILD_BENCH=OFF (no PCL)")
    builds = [args for args in shell_commands(build, "cmake") if "--build" in args]
    targets = {t for args in builds for i, word in enumerate(args[:-1]) if word == "--target" for t in args[i + 1 :]
               if not t.startswith("-")}
    problems.expect(builds and targets == {"k4reg-server", "k4reg", "k4reg-unit-tests"}, where,
                    f"the build stage must build only --target k4reg-server k4reg k4reg-unit-tests, not {sorted(targets) or 'all'}")
    image_packages = image_build_packages(d.repo)
    closure = apt_closure(tuple(image_packages)) or set(image_packages)
    for package in sorted(p for p in closure if HEAVY_BUILD_PACKAGES.match(p)):
        problems.expect(False, where, f"install-deps.sh --image pulls in {package} (PCL/VTK/Qt/MPI, a JDK, clang or a CI tool)")
    problems.expect(re.search(r"ctest\b[^&;]*-L unit", build_runs), where, "the build stage must run the unit tests (ctest -L unit)")

    packages = apt_installed(runtime)
    for package in packages:
        problems.expect(not package.endswith("-dev"), where, f"runtime package {package} is a -dev package")
        problems.expect(not BUILD_TOOLS.match(package), where, f"runtime package {package} is a build tool")
        problems.expect(not VISUALIZATION.search(package), where, f"runtime package {package} pulls in a GUI/VTK stack")
    binaries = dockerfile.copied_from(runtime, build.name)
    for name in binaries:
        problems.expect((d.bin_dir / name).is_file(), where, f"COPY --from={build.name} copies {name}, which the build does not produce")
    needed = binary_packages(tuple(d.bin_dir / name for name in binaries if (d.bin_dir / name).is_file()))
    for package in sorted(needed - set(packages)):
        problems.expect(False, where, f"the binaries need {package} (ldd + dpkg -S) but the runtime stage does not install it")
    for package in sorted(set(packages) - needed):
        problems.expect(False, where, f"runtime package {package} is not needed by the binaries (ldd + dpkg -S)")

    on_path = {name for name, (_, destination) in binaries.items() if destination in PATH_DIRS}
    entrypoint = runtime.last("ENTRYPOINT")
    argv = dockerfile.exec_form(entrypoint.arguments) if entrypoint else None
    if problems.expect(argv, where, "ENTRYPOINT must be in exec form, so the server is PID 1 and receives SIGTERM"):
        problems.expect(argv[0] == "k4reg-server" and argv[0] in on_path, where, f"ENTRYPOINT runs {argv[0]}, not the k4reg-server copied to PATH")
        for flag in cli_help.flags_of(argv[1:]):
            problems.expect(flag in d.server_options, where, f"ENTRYPOINT flag {flag} is not a k4reg-server option")
    cmd = runtime.last("CMD")
    problems.expect(cmd is None or dockerfile.exec_form(cmd.arguments) is not None, where, "CMD must be in exec form")
    stop = runtime.last("STOPSIGNAL")
    problems.expect(stop is None or stop.arguments in ("SIGTERM", "15"), where, "STOPSIGNAL must be SIGTERM (the server drains on it)")

    check_env_names(d, problems, where, image_env(d))
    values = settings(d, {})
    ports = served_ports(values)
    exposed = {int(p.split("/")[0]) for i in runtime.all("EXPOSE") for p in i.arguments.split()}
    problems.expect(exposed == set(ports.values()), where, f"EXPOSE {sorted(exposed)} but the server listens on {ports}")

    health = dockerfile.healthcheck(runtime)
    if problems.expect(health and health[1], where, "needs an exec-form HEALTHCHECK running k4reg health"):
        command = health[1]
        problems.expect(command[:2] == ["k4reg", "health"] and "k4reg" in on_path, where, f"HEALTHCHECK runs {command[:2]}, not k4reg health")
        for flag in cli_help.flags_of(command[2:]):
            problems.expect(flag in d.client_options["health"], where, f"HEALTHCHECK flag {flag} is not a k4reg health option")
            problems.expect(flag not in HEALTHCHECK_FIXED_FLAGS, where,
                            f"HEALTHCHECK {flag}: leave it to K4REG_HEALTH_LISTEN (or K4REG_SERVER, K4REG_TLS, K4REG_CA_CERT), "
                            "so the check follows the container's TLS setting and ports")
        health_host = values.get("K4REG_HEALTH_LISTEN", "").rpartition(":")[0]
        problems.expect("health" in ports and health_host in ("0.0.0.0", "[::]", *LOOPBACK_HOSTS), where,
                        "the image must set K4REG_HEALTH_LISTEN to a fixed port the HEALTHCHECK can reach on loopback")
        if "--service" in command[:-1]:
            service = command[command.index("--service") + 1]
            problems.expect(service in d.health_names.values(), where, f"HEALTHCHECK --service {service!r} is not in server/observability/health.h")

    user = runtime.last("USER")
    uid = user.arguments.split(":")[0] if user else "0"
    if problems.expect(uid.isdigit() and uid != "0", where, f"USER must be a numeric non-root uid (Kubernetes runAsNonRoot), not {uid!r}"):
        problems.expect(any(uid in args[args.index("--uid") + 1 :][:1] for args in shell_commands(runtime, "useradd")
                            if "--uid" in args), where, f"no useradd creates uid {uid}")
        gid = user.arguments.split(":")[1] if ":" in user.arguments else ""
        group_ids = [args[args.index("--gid") + 1] for args in shell_commands(runtime, "groupadd") if "--gid" in args[:-1]]
        user_gids = [args[args.index("--gid") + 1] for args in shell_commands(runtime, "useradd") if "--gid" in args[:-1]]
        problems.expect(gid == uid and gid in group_ids and user_gids == [gid], where,
                        f"USER {user.arguments}: the group must be {uid} too, created by groupadd --gid {uid} and given "
                        f"to useradd --gid {uid} (groupadd: {group_ids}, useradd: {user_gids})")
    workdir = runtime.last("WORKDIR")
    created = {path for args in shell_commands(runtime, "mkdir") for path in args if not path.startswith("-")}
    for path in (values.get("K4REG_DATA_ROOT", "").split(":") + [values.get("K4REG_SPOOL_DIR", "")] +
                 [workdir.arguments if workdir else ""]):
        if path:
            problems.expect(path in created, where, f"{path} is used but never created (mkdir)")
    spool = values.get("K4REG_SPOOL_DIR", "")
    owned = {path for args in shell_commands(runtime, "chown") for path in args[1:] if not path.startswith("-")}
    problems.expect(spool in owned, where, "K4REG_SPOOL_DIR must be set and owned by the server's user (it writes uploads there)")


def image_name(d):
    return f"k4reg:{d.version}"


def compose_path(d, value):
    """A compose path with ${VAR:-default} taken at its default, relative to the compose file's folder."""
    value = re.sub(r"\$\{\w+:-([^}]*)\}", r"\1", value)
    return (d.docker / value).resolve()


def seconds(duration):
    """Compose durations: "40s", "1m30s", "90"."""
    if re.fullmatch(r"\d+(\.\d+)?", str(duration)):
        return float(duration)
    parts = re.findall(r"(\d+(?:\.\d+)?)(h|ms|m|s|us)", str(duration))
    scale = {"h": 3600, "m": 60, "s": 1, "ms": 1e-3, "us": 1e-6}
    return sum(float(n) * scale[u] for n, u in parts)


def check_stop_timeout(problems, where, timeout_s, values):
    grace = float(values["K4REG_DRAIN_GRACE_S"])
    problems.expect(timeout_s > grace + SHUTDOWN_AFTER_GRACE_S, where,
                    f"stop timeout {timeout_s:g} s does not cover the drain ({grace:g} s) + {SHUTDOWN_AFTER_GRACE_S} s shutdown")


def check_server_environment(d, problems, where, overrides):
    """Checks the variables a compose service or pod adds to the image's; returns (settings, ports)."""
    check_env_names(d, problems, where, overrides)
    for name in ("K4REG_WORKERS", "K4REG_MEMORY_BUDGET_MB"):
        problems.expect(name in overrides, where, f"must set {name}: the default follows the host, not the container's limits")
    values = settings(d, overrides)
    return values, served_ports(values)


def check_compose(d, problems):
    where = "compose.yaml"
    services = d.compose.get("services", {})
    server, load_service = services.get("server"), services.get("load")
    if not problems.expect(server and load_service, where, "needs the services server and load"):
        return
    for name, service in services.items():
        build = service.get("build", {})
        problems.expect(compose_path(d, build.get("context", ".")) / build.get("dockerfile", "Dockerfile") ==
                        (d.docker / "Dockerfile").resolve(), where, f"service {name} does not build docker/Dockerfile")
        problems.expect(service.get("image") == image_name(d), where, f"service {name}: image must be {image_name(d)}")
    values, ports = check_server_environment(d, problems, where, compose_env(d))
    published = {int(str(p).split(":")[-1].split("/")[0]) for p in server.get("ports", [])}
    problems.expect(published <= set(ports.values()) and ports["grpc"] in published, where,
                    f"server publishes {sorted(published)} but listens on {ports}")
    data_roots = [r for r in values.get("K4REG_DATA_ROOT", "").split(":") if r]
    mounts = [v for v in server.get("volumes", []) if isinstance(v, dict) and v.get("target") in data_roots]
    scans = None
    if problems.expect(mounts, where, f"server must bind-mount the data root {data_roots}"):
        problems.expect(mounts[0].get("type") == "bind" and mounts[0].get("read_only") is True, where,
                        "the data root must be a read-only bind mount")
        scans = compose_path(d, mounts[0].get("source", ""))
        problems.expect(scans.is_dir(), where, f"the default scans folder {scans} does not exist")
    check_stop_timeout(problems, where, seconds(server.get("stop_grace_period", "10s")), values)

    problems.expect(load_service.get("entrypoint") == ["k4reg"], where, "load: entrypoint must be [\"k4reg\"]")
    command = load_service.get("command", [])
    if problems.expect(command[:1] == ["load"], where, "load: command must start with load"):
        for flag in cli_help.flags_of(command[1:]):
            problems.expect(flag in d.client_options["load"], where, f"load: {flag} is not a k4reg load option")
        target = command[command.index("--server") + 1] if "--server" in command[:-1] else ""
        problems.expect(target == f"server:{ports['grpc']}", where, f"load: --server {target!r}, the server is server:{ports['grpc']}")
        for i, word in enumerate(command):
            if word == "--pair" and scans is not None:
                for path in command[i + 1 : i + 3]:
                    problems.expect((scans / path).is_file(), where, f"load: --pair file {path} is not in {scans}")
    problems.expect(load_service.get("depends_on", {}).get("server", {}).get("condition") == "service_healthy",
                    where, "load must wait for server: condition service_healthy")
    problems.expect(load_service.get("healthcheck", {}).get("disable") is True, where,
                    "load must disable the image's HEALTHCHECK (it has no server on localhost)")


def quantity(value):
    """Kubernetes quantities: CPU in cores ("2", "500m"), memory in MiB ("4Gi", "512Mi", "4G")."""
    value = str(value)
    units = {"m": 1e-3, "Ki": 1 / 1024, "Mi": 1, "Gi": 1024, "Ti": 1024**2, "k": 1e3 / 2**20, "M": 1e6 / 2**20,
             "G": 1e9 / 2**20, "T": 1e12 / 2**20}
    match = re.fullmatch(r"(\d+(?:\.\d+)?)([A-Za-z]*)", value)
    if not match or match.group(2) not in units and match.group(2):
        raise ValueError(f"unreadable quantity {value!r}")
    return float(match.group(1)) * (units[match.group(2)] if match.group(2) else 1)


def selects(selector, labels):
    return bool(selector) and all(labels.get(k) == v for k, v in selector.items())


def check_kubernetes(d, problems):
    kustomization = yaml.safe_load((d.docker / "k8s/kustomization.yaml").read_text())
    resources = kustomization.get("resources", [])
    files = sorted(p.name for p in (d.docker / "k8s").glob("*.yaml") if p.name != "kustomization.yaml")
    problems.expect(sorted(resources) == files, "k8s/kustomization.yaml", f"resources {sorted(resources)} must be exactly {files}")

    where, deployment = d.deployment()
    if not problems.expect(deployment, "k8s", "needs a Deployment"):
        return
    pod = deployment["spec"]["template"]
    labels = pod["metadata"].get("labels", {})
    problems.expect(selects(deployment["spec"]["selector"].get("matchLabels"), labels), where, "selector does not match the pod labels")
    container = k8s_container(d)
    problems.expect(container.get("image") == image_name(d), where, f"image must be {image_name(d)} (as in compose.yaml)")
    values, ports = check_server_environment(d, problems, where, k8s_env(d))
    container_ports = {p.get("name"): p["containerPort"] for p in container.get("ports", [])}
    problems.expect(container_ports == ports, where, f"container ports {container_ports} but the server listens on {ports}")
    if k8s_scrape_path(d):
        scrape_port = pod["metadata"]["annotations"].get("prometheus.io/port")
        problems.expect(scrape_port == str(ports.get("http")), where, f"prometheus.io/port {scrape_port} is not the HTTP port")

    for probe, name in (("livenessProbe", "kLivenessService"), ("readinessProbe", "kReadinessService")):
        grpc = container.get(probe, {}).get("grpc", {})
        # Kubernetes' gRPC probes speak no TLS: they must go to the plaintext health-only listener.
        problems.expect(grpc.get("port") == ports.get("health"), where,
                        f"{probe} must use the health listener's port {ports.get('health')} (K4REG_HEALTH_LISTEN)")
        problems.expect(grpc.get("service") == d.health_names.get(name), where,
                        f"{probe} service {grpc.get('service')!r} must be {d.health_names.get(name)!r} (server/observability/health.h)")
    check_stop_timeout(problems, where, pod["spec"].get("terminationGracePeriodSeconds", 30), values)
    problems.expect(float(values["K4REG_MAX_CONNECTION_AGE_S"]) > 0, where,
                    "K4REG_MAX_CONNECTION_AGE_S must be set, so long-lived HTTP/2 connections rebalance over replicas")

    resources = container.get("resources", {})
    requests, limits = resources.get("requests", {}), resources.get("limits", {})
    if problems.expect("cpu" in requests and "memory" in limits, where, "needs a CPU request (for the HPA) and a memory limit"):
        cores = quantity(limits.get("cpu", requests["cpu"]))
        workers, job_threads = int(values.get("K4REG_WORKERS") or 0), int(values["K4REG_JOB_THREADS"])
        problems.expect(0 < workers * job_threads <= cores, where,
                        f"K4REG_WORKERS x K4REG_JOB_THREADS = {workers * job_threads} threads on {cores:g} cores")
        budget = int(values.get("K4REG_MEMORY_BUDGET_MB") or 0)
        inline = int(values["K4REG_MAX_INLINE_MB"]) * (workers + int(values["K4REG_QUEUE_SIZE"]))
        # Peers' pair jobs are held in memory while they wait and run, beside the budget their registration uses.
        pair_workers = int(values.get("K4REG_PAIR_WORKERS") or 0) or workers
        pairs = math.ceil(float(values["K4REG_MAX_PAIR_MB"]) * (pair_workers + int(values["K4REG_PAIR_QUEUE_SIZE"])))
        pairs += int(values["K4REG_PAIR_CACHE_MB"])  # their scans, kept with their preparation
        # Messages still arriving, before any token is checked (server_config.cpp: half the budget by default).
        receiving = int(values.get("K4REG_GRPC_RECEIVE_QUOTA_MB") or 0) or max(budget // 2, 64)
        needed = budget + inline + pairs + receiving + PROCESS_OVERHEAD_MIB
        problems.expect(0 < budget and needed <= quantity(limits["memory"]), where,
                        f"memory limit {limits['memory']} < budget {budget} + inline requests {inline} + pair jobs "
                        f"and their kept scans {pairs} + gRPC messages arriving {receiving} + process "
                        f"{PROCESS_OVERHEAD_MIB} MiB")

    check_pod_isolation(problems, where, pod, container, values)

    security = {**pod["spec"].get("securityContext", {}), **container.get("securityContext", {})}
    problems.expect(security.get("runAsNonRoot") is True, where, "runAsNonRoot must be true")
    user = d.runtime.last("USER")
    if "runAsUser" in security and user:
        problems.expect(str(security["runAsUser"]) == user.arguments.split(":")[0], where, "runAsUser differs from the image's USER")
    mounts = {m["mountPath"]: m for m in container.get("volumeMounts", [])}
    if security.get("readOnlyRootFilesystem"):
        spool = mounts.get(values.get("K4REG_SPOOL_DIR"))
        problems.expect(spool and not spool.get("readOnly"), where,
                        "the root filesystem is read-only: K4REG_SPOOL_DIR needs a writable volume")
    for root in filter(None, values.get("K4REG_DATA_ROOT", "").split(":")):
        if root in mounts:
            problems.expect(mounts[root].get("readOnly") is True, where, f"the data root {root} must be mounted readOnly")

    check_services(d, problems, labels, container, ports)
    check_network_policy(d, problems, labels, container)
    check_scaling(d, problems, deployment, labels)


def check_pod_isolation(problems, where, pod, container, values):
    """No API credentials in the pod, the tokens from a Secret, the disk the spool may fill within a limit."""
    problems.expect(pod["spec"].get("automountServiceAccountToken") is False, where,
                    "automountServiceAccountToken must be false: the server needs no Kubernetes API credentials")
    for name in ("K4REG_AUTH_TOKEN", "K4REG_PEER_TOKEN"):
        problems.expect(str(values.get(name, "")).startswith("<secret:"), where,
                        f"{name} must come from a Secret (valueFrom.secretKeyRef), never a literal in the manifest")
    resources = container.get("resources", {})
    requests, limits = resources.get("requests", {}), resources.get("limits", {})
    if problems.expect("ephemeral-storage" in requests and "ephemeral-storage" in limits, where,
                       "needs ephemeral-storage requests and limits (the upload spool)"):
        mounts = {m["name"]: m["mountPath"] for m in container.get("volumeMounts", [])}
        for volume in pod["spec"].get("volumes", []):
            size = volume.get("emptyDir", {}).get("sizeLimit")
            if size and mounts.get(volume["name"]) == values.get("K4REG_SPOOL_DIR"):
                problems.expect(quantity(limits["ephemeral-storage"]) >= quantity(size), where,
                                f"ephemeral-storage limit {limits['ephemeral-storage']} is below the spool volume's sizeLimit {size}")


def check_network_policy(d, problems, labels, container):
    """The API ports only from chosen sources (and the replicas, for pair jobs), the health port for the probes."""
    policies = d.kind("NetworkPolicy")
    if not problems.expect(policies, "k8s", "needs a NetworkPolicy limiting who reaches the API ports"):
        return
    names = {p.get("name"): p["containerPort"] for p in container.get("ports", [])}
    for where, policy in policies:
        spec = policy["spec"]
        problems.expect(selects(spec.get("podSelector", {}).get("matchLabels"), labels), where,
                        "podSelector does not match the pod labels")
        problems.expect("Ingress" in spec.get("policyTypes", []), where, "must restrict Ingress")
        reachable, from_everywhere, from_replicas = set(), set(), set()
        for rule in spec.get("ingress", []):
            ports = {names.get(p.get("port"), p.get("port")) for p in rule.get("ports", [])} or set(names.values())
            sources = rule.get("from", [])
            reachable |= ports
            if not sources or any(s.get("ipBlock", {}).get("cidr") in ("0.0.0.0/0", "::/0") for s in sources):
                from_everywhere |= ports
            if any(selects(s.get("podSelector", {}).get("matchLabels"), labels) and "namespaceSelector" not in s
                   for s in sources):
                from_replicas |= ports
        problems.expect(names.get("health") in reachable, where, "the probes must reach the health port")
        for api in ("grpc", "http"):
            problems.expect(names.get(api) in reachable and names.get(api) not in from_everywhere, where,
                            f"the {api} port must be reachable from the allowed namespaces only, not from everywhere")
        problems.expect(names.get("grpc") in from_replicas, where, "the replicas must reach each other's gRPC port (pair jobs)")


def check_services(d, problems, labels, container, ports):
    names = {p.get("name"): p["containerPort"] for p in container.get("ports", [])}
    services = d.kind("Service")
    headless = [(w, s) for w, s in services if s["spec"].get("clusterIP") == "None"]
    problems.expect(headless and len(services) > len(headless), "k8s",
                    "needs a headless Service (clusterIP: None) for client-side round robin and a regular Service")
    for where, service in services:
        problems.expect(selects(service["spec"].get("selector"), labels), where, "selector does not match the pod labels")
        for port in service["spec"].get("ports", []):
            target = port.get("targetPort", port["port"])
            number = names.get(target) if isinstance(target, str) else target
            problems.expect(number in names.values(), where, f"targetPort {target!r} is not a container port")
    for where, service in headless:
        # Clients dial the pod IPs DNS returns with the port of their target: it must be the container's.
        grpc = [p for p in service["spec"].get("ports", []) if p["port"] == ports["grpc"]]
        problems.expect(grpc and names.get(grpc[0].get("targetPort"), grpc[0].get("targetPort")) == ports["grpc"], where,
                        f"the headless Service must expose the gRPC port {ports['grpc']} as itself")


def check_scaling(d, problems, deployment, labels):
    hpas = d.kind("HorizontalPodAutoscaler")
    min_replicas = 1
    if problems.expect(hpas, "k8s", "needs a HorizontalPodAutoscaler"):
        where, hpa = hpas[0]
        problems.expect(hpa.get("apiVersion") == "autoscaling/v2", where, "must be autoscaling/v2")
        target = hpa["spec"].get("scaleTargetRef", {})
        problems.expect(target.get("kind") == "Deployment" and target.get("name") == deployment["metadata"]["name"], where,
                        f"scaleTargetRef must be the Deployment {deployment['metadata']['name']}")
        problems.expect(any(m.get("resource", {}).get("name") == "cpu" for m in hpa["spec"].get("metrics", [])), where,
                        "must scale on CPU")
        problems.expect("replicas" not in deployment["spec"], "deployment", "no replicas field: the HPA owns the count")
        min_replicas = hpa["spec"].get("minReplicas", 1)
    pdbs = d.kind("PodDisruptionBudget")
    if problems.expect(pdbs, "k8s", "needs a PodDisruptionBudget"):
        where, pdb = pdbs[0]
        problems.expect(selects(pdb["spec"].get("selector", {}).get("matchLabels"), labels), where, "selector does not match the pod labels")
        min_available = pdb["spec"].get("minAvailable", min_replicas - pdb["spec"].get("maxUnavailable", 0))
        problems.expect(isinstance(min_available, int) and min_available < min_replicas, where,
                        f"with {min_replicas} replicas it would block every voluntary disruption")


def check(repo, bin_dir, docker_dir=None):
    """The problems found, as "file: message" lines; empty when docker/ agrees with the programs."""
    try:
        d = load(repo, bin_dir, docker_dir)
    except (OSError, ValueError, yaml.YAMLError) as error:
        return [f"cannot read the files: {error}"]
    problems = Problems()
    for part in (check_dockerfile, check_compose, check_kubernetes, check_mentioned_variables):
        try:
            part(d, problems)
        except (KeyError, TypeError, ValueError, IndexError, AttributeError) as error:
            problems.append(f"{part.__name__}: cannot read the files ({type(error).__name__}: {error})")
    return problems


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repo", default=Path(__file__).resolve().parents[2], type=Path)
    parser.add_argument("--bin-dir", required=True, type=Path, help="folder with the built k4reg-server and k4reg")
    parser.add_argument("--docker-dir", type=Path, help="default: REPO/docker")
    args = parser.parse_args()
    problems = check(args.repo, args.bin_dir, args.docker_dir)
    for problem in problems:
        print(problem)
    print(f"deployment check: {len(problems)} problem(s)", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
