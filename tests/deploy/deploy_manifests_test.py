#!/usr/bin/env python3
# SPDX-License-Identifier: AGPL-3.0-or-later
"""The deployment files, checked offline: deploy/kubernetes and deploy/compose.yaml.

Loads every manifest the kustomization lists and asserts what a cluster would
only show at run time: the restricted Pod Security profile on every pod,
requests and limits, a worker memory limit that holds its jobs' address-space
limits, gRPC probes on 50051, grace periods longer than labelmeshd's, selectors
(Services, disruption budgets, network policies, the ScaledObject) that find
their pods, the job queue's real names, and only LABELMESHD_* variables that
labelmeshd reads. The same checks run on `kubectl kustomize` output when
kubectl is installed, and on the Compose file's default and "scaled" profiles.
Then each check is shown to bite: a broken copy of the files must fail it.
"""
import argparse
import copy
import pathlib
import re
import shutil
import subprocess
import sys

import yaml

NAME = "app.kubernetes.io/name"
COMPONENT = "app.kubernetes.io/component"
COMPONENTS = {"frontend", "worker", "nats"}
UID = 10001
GRPC_PORT = 50051
METRICS_PORT = 9464
NATS_CLIENT_PORT = 4222
NATS_MONITOR_PORT = 8222
# What labelmeshd keeps for itself besides its jobs' address space.
MIN_HEADROOM_BYTES = 512 << 20
DEFAULT_SHUTDOWN_GRACE = "30s"  # labelmeshd --shutdown-grace
# Volume types the restricted profile allows.
RESTRICTED_VOLUMES = {"configMap", "csi", "downwardAPI", "emptyDir", "ephemeral",
                      "persistentVolumeClaim", "projected", "secret"}

UNITS = {"": 1, "k": 10**3, "M": 10**6, "G": 10**9, "T": 10**12, "P": 10**15,
         "Ki": 2**10, "Mi": 2**20, "Gi": 2**30, "Ti": 2**40, "Pi": 2**50, "m": 1e-3}


def quantity(text):
    """A Kubernetes quantity ("9Gi", "250m", "2") as a number."""
    match = re.fullmatch(r"(\d+(?:\.\d+)?)(Ki|Mi|Gi|Ti|Pi|k|M|G|T|P|m)?", str(text))
    if not match:
        raise ValueError(f"not a quantity: {text!r}")
    return float(match.group(1)) * UNITS[match.group(2) or ""]


def duration_seconds(text):
    """An abseil duration as labelmeshd parses it ("30s", "2m", "1h30m")."""
    parts = re.findall(r"(\d+(?:\.\d+)?)(h|ms|m|s)", text)
    if not parts or "".join(n + u for n, u in parts) != text:
        raise ValueError(f"not a duration: {text!r}")
    scale = {"h": 3600, "m": 60, "s": 1, "ms": 1e-3}
    return sum(float(n) * scale[u] for n, u in parts)


def matches(selector, labels):
    return bool(selector) and all(labels.get(k) == v for k, v in selector.items())


class Checks:
    """Problems found in one set of manifests, as readable lines."""

    def __init__(self, known_env, queue_names, liveness_service):
        self.known_env = known_env
        self.liveness_service = liveness_service
        self.queue_names = queue_names
        self.problems = []

    def require(self, condition, message):
        if not condition:
            self.problems.append(message)
        return condition

    # --- Kubernetes -------------------------------------------------------

    def kubernetes(self, docs, namespace=None):
        """All checks on the objects `docs`; `namespace` is the one the
        ScaledObject's NATS address must name (None: not rendered yet)."""
        self.docs = docs
        self.workloads = [d for d in docs if d["kind"] in ("Deployment", "StatefulSet")]
        for doc in docs:
            self.labels(doc)
        for workload in self.workloads:
            self.pod_security(workload)
            self.resources(workload)
        for container, workload in self.labelmeshd_containers():
            self.probes_and_grace(container, workload)
            self.cluster_env(container, workload)
        self.frontend_replicas()
        self.worker_memory()
        self.services()
        self.disruption_budgets()
        self.network_policies()
        self.nats()
        self.scaled_object(namespace)

    def kind(self, kind):
        return [d for d in self.docs if d["kind"] == kind]

    def pod_labels(self, workload):
        return workload["spec"]["template"]["metadata"].get("labels", {})

    def selected(self, selector):
        return [w for w in self.workloads if matches(selector, self.pod_labels(w))]

    def component(self, name):
        found = [w for w in self.workloads if self.pod_labels(w).get(COMPONENT) == name]
        self.require(len(found) == 1, f"expected one {name} workload, found {len(found)}")
        return found[0] if found else None

    def containers(self, workload):
        spec = workload["spec"]["template"]["spec"]
        return spec.get("initContainers", []) + spec.get("containers", [])

    def labelmeshd_containers(self):
        for workload in self.workloads:
            for container in self.containers(workload):
                if container.get("command", [""])[0] == "labelmeshd":
                    yield container, workload

    @staticmethod
    def env(container):
        return {e["name"]: e.get("value") for e in container.get("env", [])}

    @staticmethod
    def container_ports(workload):
        ports = {}
        for container in workload["spec"]["template"]["spec"]["containers"]:
            for port in container.get("ports", []):
                ports[port["containerPort"]] = port["containerPort"]
                if "name" in port:
                    ports[port["name"]] = port["containerPort"]
        return ports

    def labels(self, doc):
        meta = doc["metadata"]
        where = f"{doc['kind']} {meta['name']}"
        labels = meta.get("labels", {})
        self.require(labels.get(NAME) == "labelmesh", f"{where}: {NAME} is not labelmesh")
        if doc["kind"] in ("Namespace", "PersistentVolumeClaim"):
            return
        self.require(labels.get(COMPONENT) in COMPONENTS,
                     f"{where}: {COMPONENT} is not one of {sorted(COMPONENTS)}")
        if doc in self.workloads:
            pod = self.pod_labels(doc)
            self.require(matches(doc["spec"]["selector"].get("matchLabels"), pod),
                         f"{where}: its selector does not select its own pods")
            self.require(pod.get(NAME) == "labelmesh" and
                         pod.get(COMPONENT) == labels.get(COMPONENT),
                         f"{where}: pod labels differ from the workload's")

    def pod_security(self, workload):
        """The restricted Pod Security profile, and the house rules on top."""
        where = f"{workload['kind']} {workload['metadata']['name']}"
        spec = workload["spec"]["template"]["spec"]
        pod = spec.get("securityContext", {})
        for field in ("hostNetwork", "hostPID", "hostIPC"):
            self.require(not spec.get(field), f"{where}: {field}")
        self.require(spec.get("automountServiceAccountToken") is False,
                     f"{where}: mounts a service account token")
        volumes = {v["name"]: v for v in spec.get("volumes", [])}
        for name, volume in volumes.items():
            kinds = set(volume) - {"name"}
            self.require(kinds <= RESTRICTED_VOLUMES, f"{where}: volume {name} is {kinds}")
        for container in self.containers(workload):
            cwhere = f"{where} container {container['name']}"
            own = container.get("securityContext", {})

            def effective(field):
                return own.get(field, pod.get(field))

            self.require(effective("runAsNonRoot") is True, f"{cwhere}: runAsNonRoot is not true")
            self.require(effective("runAsUser") == UID, f"{cwhere}: runAsUser is not {UID}")
            self.require((effective("seccompProfile") or {}).get("type") == "RuntimeDefault",
                         f"{cwhere}: seccompProfile is not RuntimeDefault")
            self.require(own.get("allowPrivilegeEscalation") is False,
                         f"{cwhere}: allowPrivilegeEscalation is not false")
            self.require(not own.get("privileged"), f"{cwhere}: privileged")
            caps = own.get("capabilities", {})
            self.require("ALL" in caps.get("drop", []), f"{cwhere}: does not drop ALL capabilities")
            self.require(set(caps.get("add", [])) <= {"NET_BIND_SERVICE"},
                         f"{cwhere}: adds capabilities {caps.get('add')}")
            self.require(own.get("readOnlyRootFilesystem") is True,
                         f"{cwhere}: root file system is writable")
            self.require(all("hostPort" not in p for p in container.get("ports", [])),
                         f"{cwhere}: uses a hostPort")
            tmp = [m for m in container.get("volumeMounts", []) if m["mountPath"] == "/tmp"]
            self.require(tmp and "emptyDir" in volumes.get(tmp[0]["name"], {}),
                         f"{cwhere}: /tmp is not an emptyDir")

    def resources(self, workload):
        for container in self.containers(workload):
            where = f"{workload['metadata']['name']} container {container['name']}"
            res = container.get("resources", {})
            for kind in ("cpu", "memory"):
                request = res.get("requests", {}).get(kind)
                limit = res.get("limits", {}).get(kind)
                if self.require(request is not None and limit is not None,
                                f"{where}: no {kind} request and limit"):
                    self.require(quantity(request) <= quantity(limit),
                                 f"{where}: {kind} request {request} over its limit {limit}")

    def probes_and_grace(self, container, workload):
        where = workload["metadata"]["name"]
        env = self.env(container)
        listen = env.get("LABELMESHD_LISTEN", "")
        self.require(listen.endswith(f":{GRPC_PORT}"), f"{where}: listens on {listen!r}")
        self.require(GRPC_PORT in self.container_ports(workload),
                     f"{where}: no containerPort {GRPC_PORT}")
        for probe in ("livenessProbe", "readinessProbe", "startupProbe"):
            if probe not in container and probe == "startupProbe":
                continue
            grpc = container.get(probe, {}).get("grpc", {})
            self.require(grpc.get("port") == GRPC_PORT,
                         f"{where}: {probe} is not a grpc probe on {GRPC_PORT}")
        # Liveness must not follow readiness: it asks the service that
        # answers while the process serves (kLivenessService).
        liveness = container.get("livenessProbe", {}).get("grpc", {}).get("service")
        self.require(liveness == self.liveness_service,
                     f"{where}: livenessProbe asks service {liveness!r}, not "
                     f"{self.liveness_service!r}")
        grace = duration_seconds(env.get("LABELMESHD_SHUTDOWN_GRACE") or DEFAULT_SHUTDOWN_GRACE)
        period = workload["spec"]["template"]["spec"].get("terminationGracePeriodSeconds", 30)
        self.require(period > grace, f"{where}: terminationGracePeriodSeconds {period} is not "
                                     f"longer than the shutdown grace ({grace:g} s)")

    def cluster_env(self, container, workload):
        where = workload["metadata"]["name"]
        env = self.env(container)
        for name in env:
            if name.startswith("LABELMESHD_"):
                self.require(name in self.known_env, f"{where}: labelmeshd has no {name}")
        role = env.get("LABELMESHD_ROLE")
        self.require(role == self.pod_labels(workload).get(COMPONENT),
                     f"{where}: LABELMESHD_ROLE {role!r} is not its component")
        url = re.fullmatch(r"nats://([a-z0-9.-]+):(\d+)", env.get("LABELMESHD_NATS_URL") or "")
        if self.require(url, f"{where}: LABELMESHD_NATS_URL is not nats://HOST:PORT"):
            self.nats_service(url.group(1).split(".")[0], int(url.group(2)), where)
        spec = workload["spec"]["template"]["spec"]
        claims = {v["name"]: v["persistentVolumeClaim"]["claimName"]
                  for v in spec.get("volumes", []) if "persistentVolumeClaim" in v}
        mounts = {m["mountPath"]: m["name"] for m in container.get("volumeMounts", [])}
        claim = claims.get(mounts.get(env.get("LABELMESHD_ARTIFACT_DIR")))
        shared = [p for p in self.kind("PersistentVolumeClaim") if p["metadata"]["name"] == claim]
        self.require(shared and "ReadWriteMany" in shared[0]["spec"].get("accessModes", []),
                     f"{where}: LABELMESHD_ARTIFACT_DIR is not on a ReadWriteMany claim")

    def nats_service(self, name, port, where):
        """`name`:`port` must be a Service that reaches NATS's `port`."""
        services = [s for s in self.kind("Service") if s["metadata"]["name"] == name]
        if not self.require(services, f"{where}: no Service {name}"):
            return
        nats = self.selected(services[0]["spec"].get("selector"))
        self.require(nats and all(self.pod_labels(w).get(COMPONENT) == "nats" for w in nats),
                     f"{where}: Service {name} does not select the NATS pods")
        self.require(any(p["port"] == port for p in services[0]["spec"]["ports"]),
                     f"{where}: Service {name} has no port {port}")

    def frontend_replicas(self):
        frontend = self.component("frontend")
        if frontend:
            self.require(frontend["spec"].get("replicas") == 2, "frontend: replicas is not 2")

    def worker_memory(self):
        worker = self.component("worker")
        if not worker:
            return
        for container in worker["spec"]["template"]["spec"]["containers"]:
            env = self.env(container)
            if "LABELMESHD_WORKERS" not in env:
                self.require(False, "worker: LABELMESHD_WORKERS unset (the default follows the "
                                    "node's cores, not the pod's limits)")
                continue
            jobs = int(env["LABELMESHD_WORKERS"])
            per_job = int(env.get("LABELMESHD_WORKER_MEMORY_BYTES", 8 << 30))
            self.require(per_job > 0, "worker: no address-space limit per job")
            limit = quantity(container["resources"]["limits"]["memory"])
            self.require(limit >= jobs * per_job + MIN_HEADROOM_BYTES,
                         f"worker: memory limit {limit / 2**30:g} GiB is under {jobs} jobs x "
                         f"{per_job / 2**30:g} GiB + {MIN_HEADROOM_BYTES >> 20} MiB")

    def services(self):
        for service in self.kind("Service"):
            where = f"Service {service['metadata']['name']}"
            pods = self.selected(service["spec"].get("selector"))
            if not self.require(pods, f"{where}: selects no pods"):
                continue
            for port in service["spec"]["ports"]:
                target = port.get("targetPort", port["port"])
                self.require(all(target in self.container_ports(w) for w in pods),
                             f"{where}: targetPort {target} is not a port of its pods")
        frontend = [s for s in self.kind("Service")
                    if s["metadata"].get("labels", {}).get(COMPONENT) == "frontend"]
        ports = {p["port"] for s in frontend for p in s["spec"]["ports"]}
        self.require({GRPC_PORT, METRICS_PORT} <= ports,
                     f"frontend Service: ports {sorted(ports)} lack {GRPC_PORT} or {METRICS_PORT}")

    def disruption_budgets(self):
        covered = []
        for pdb in self.kind("PodDisruptionBudget"):
            where = f"PodDisruptionBudget {pdb['metadata']['name']}"
            pods = self.selected(pdb["spec"]["selector"].get("matchLabels"))
            if not self.require(len(pods) == 1 and pods[0]["kind"] == "Deployment",
                                f"{where}: does not select exactly one Deployment"):
                continue
            covered.append(self.pod_labels(pods[0]).get(COMPONENT))
            replicas = pods[0]["spec"].get("replicas")
            if "minAvailable" in pdb["spec"] and replicas is not None:
                self.require(pdb["spec"]["minAvailable"] < replicas,
                             f"{where}: minAvailable blocks every eviction")
        self.require(sorted(covered) == ["frontend", "worker"],
                     f"disruption budgets cover {sorted(covered)}, not frontend and worker")

    def network_policies(self):
        ports_of = {}
        for policy in self.kind("NetworkPolicy"):
            where = f"NetworkPolicy {policy['metadata']['name']}"
            pods = self.selected(policy["spec"]["podSelector"].get("matchLabels"))
            if not self.require(pods, f"{where}: selects no pods"):
                continue
            component = self.pod_labels(pods[0]).get(COMPONENT)
            allowed = ports_of.setdefault(component, {})
            for rule in policy["spec"].get("ingress", []):
                sources = []
                for peer in rule.get("from", []):
                    if "podSelector" in peer and "namespaceSelector" not in peer:
                        found = self.selected(peer["podSelector"].get("matchLabels"))
                        self.require(found, f"{where}: a podSelector in from selects no pods")
                        sources += [self.pod_labels(w).get(COMPONENT) for w in found]
                    else:
                        sources.append("outside")
                for port in rule.get("ports", []):
                    self.require(all(port["port"] in self.container_ports(w) for w in pods),
                                 f"{where}: port {port['port']} is not a port of its pods")
                    allowed.setdefault(port["port"], set()).update(sources or {"anyone"})
        self.require(set(ports_of.get("frontend", {})) == {GRPC_PORT, METRICS_PORT},
                     f"frontend pods accept {sorted(ports_of.get('frontend', {}))}")
        if self.require(ports_of.get("worker"), "worker pods have no NetworkPolicy"):
            self.require(set(ports_of["worker"]) <= {GRPC_PORT, METRICS_PORT},
                         "worker pods accept more than probes and metrics")
        nats = ports_of.get("nats", {})
        self.require(nats.get(NATS_CLIENT_PORT) == {"frontend", "worker"},
                     f"NATS clients admitted from {nats.get(NATS_CLIENT_PORT)}, "
                     "not only frontends and workers")
        self.require(all("anyone" not in who for who in nats.values()) and nats,
                     "NATS accepts connections from anyone")

    def nats(self):
        nats = self.component("nats")
        if not nats:
            return
        self.require(nats["kind"] == "StatefulSet", "NATS is not a StatefulSet")
        args = [a for c in nats["spec"]["template"]["spec"]["containers"]
                for a in c.get("command", []) + c.get("args", [])]
        self.require("-js" in args, "NATS runs without -js (JetStream)")
        self.require(["-m", str(NATS_MONITOR_PORT)] in [args[i:i + 2] for i in range(len(args))],
                     f"NATS runs without -m {NATS_MONITOR_PORT} (KEDA reads the lag there)")
        store = args[args.index("-sd") + 1] if "-sd" in args[:-1] else None
        claims = {t["metadata"]["name"] for t in nats["spec"].get("volumeClaimTemplates", [])}
        mounts = {m["mountPath"]: m["name"]
                  for c in nats["spec"]["template"]["spec"]["containers"]
                  for m in c.get("volumeMounts", [])}
        self.require(store and mounts.get(store) in claims,
                     f"NATS stores JetStream in {store!r}, not on its claim")
        headless = [s for s in self.kind("Service")
                    if s["metadata"]["name"] == nats["spec"].get("serviceName")]
        self.require(headless and headless[0]["spec"].get("clusterIP") == "None",
                     "NATS's serviceName is not a headless Service")

    def scaled_object(self, namespace):
        objects = self.kind("ScaledObject")
        if not self.require(len(objects) == 1, f"{len(objects)} ScaledObjects, not one"):
            return
        spec = objects[0]["spec"]
        target = spec["scaleTargetRef"]
        worker = self.component("worker")
        self.require(worker and target.get("kind", "Deployment") == worker["kind"] == "Deployment"
                     and target["name"] == worker["metadata"]["name"],
                     f"ScaledObject scales {target.get('kind')} {target['name']}, not the workers")
        if worker:
            self.require("replicas" not in worker["spec"],
                         "worker Deployment sets replicas: each apply would undo KEDA's count")
        self.require(1 <= spec.get("minReplicaCount", 0) <= spec.get("maxReplicaCount", 100),
                     "ScaledObject replica bounds")
        triggers = [t for t in spec["triggers"] if t["type"] == "nats-jetstream"]
        if not self.require(triggers, "ScaledObject has no nats-jetstream trigger"):
            return
        meta = triggers[0]["metadata"]
        stream, consumer = self.queue_names
        self.require(meta.get("stream") == stream, f"trigger stream {meta.get('stream')!r}")
        self.require(meta.get("consumer") == consumer,
                     f"trigger consumer {meta.get('consumer')!r}")
        self.require(meta.get("account") == "$G", "trigger account is not NATS's global $G")
        if worker:
            jobs = self.env(worker["spec"]["template"]["spec"]["containers"][0]).get(
                "LABELMESHD_WORKERS")
            self.require(meta.get("lagThreshold") == jobs,
                         f"lagThreshold {meta.get('lagThreshold')} is not LABELMESHD_WORKERS")
        endpoint = re.fullmatch(r"([a-z0-9-]+)\.([a-z0-9-]+)\.svc(\.[a-z0-9.-]+)?:(\d+)",
                                meta.get("natsServerMonitoringEndpoint", ""))
        if self.require(endpoint, "natsServerMonitoringEndpoint is not SERVICE.NAMESPACE.svc:PORT"):
            self.nats_service(endpoint.group(1), int(endpoint.group(4)), "ScaledObject")
            self.require(int(endpoint.group(4)) == NATS_MONITOR_PORT,
                         "natsServerMonitoringEndpoint is not the monitoring port")
            if namespace is not None:
                self.require(endpoint.group(2) == namespace,
                             f"natsServerMonitoringEndpoint names namespace "
                             f"{endpoint.group(2)!r}, not {namespace!r}")

    # --- Compose ----------------------------------------------------------

    def compose(self, compose):
        services = compose["services"]
        named_volumes = set(compose.get("volumes") or {})

        def env(service):
            value = service.get("environment", {})
            if isinstance(value, list):
                value = dict(item.split("=", 1) for item in value)
            return value

        default = sorted(n for n, s in services.items() if not s.get("profiles"))
        self.require(default == ["labelmeshd"], f"default profile runs {default}")
        labelmesh = {n: s for n, s in services.items()
                     if str(s.get("image", "")).startswith("labelmesh:")}
        for name, service in labelmesh.items():
            self.require(service.get("read_only") is True, f"compose {name}: writable root")
            self.require("ALL" in service.get("cap_drop", []), f"compose {name}: capabilities")
            self.require("no-new-privileges:true" in service.get("security_opt", []),
                         f"compose {name}: privileges may grow")
            self.require("/tmp" in service.get("tmpfs", []), f"compose {name}: no tmpfs /tmp")
            for port in service.get("ports", []):
                self.require(str(port).startswith("127.0.0.1:"),
                             f"compose {name}: port {port} not on loopback")
            for key in env(service):
                if key.startswith("LABELMESHD_"):
                    self.require(key in self.known_env, f"compose {name}: labelmeshd has no {key}")
            if service.get("command", [""])[0] == "labelmeshd":
                grace = duration_seconds(env(service).get("LABELMESHD_SHUTDOWN_GRACE",
                                                          DEFAULT_SHUTDOWN_GRACE))
                stop = duration_seconds(service.get("stop_grace_period", "10s"))
                self.require(stop > grace, f"compose {name}: stop_grace_period {stop:g} s is "
                                           f"not longer than the shutdown grace {grace:g} s")
        spool = services.get("labelmeshd", {})
        self.require("spool:/data/spool" in spool.get("volumes", []) and
                     "127.0.0.1:50051:50051" in spool.get("ports", []),
                     "compose labelmeshd: no longer the single-node service")

        scaled = {n: s for n, s in services.items() if "scaled" in s.get("profiles", [])}
        nats = [n for n, s in scaled.items() if "-js" in s.get("command", [])]
        if not self.require(len(nats) == 1, f"compose scaled: {len(nats)} NATS with -js"):
            return
        command = scaled[nats[0]]["command"]
        store = command[command.index("-sd") + 1] if "-sd" in command[:-1] else None
        self.require(any(v.split(":")[0] in named_volumes and v.split(":")[1] == store
                         for v in scaled[nats[0]].get("volumes", [])),
                     f"compose {nats[0]}: JetStream store {store!r} is not on a named volume")
        replicas = {"frontend": 0, "worker": 0}
        host_ports, artifact_volumes = [], set()
        for name, service in scaled.items():
            role = env(service).get("LABELMESHD_ROLE")
            if name in nats:
                continue
            if not self.require(role in replicas, f"compose {name}: role {role!r}"):
                continue
            replicas[role] += service.get("deploy", {}).get("replicas", 1)
            if role == "frontend":
                self.require(service.get("deploy", {}).get("replicas", 1) == 1,
                             f"compose {name}: replicas would share its host ports")
                host_ports += [p.split(":")[1] for p in service.get("ports", [])
                               if p.endswith(f":{GRPC_PORT}")]
            url = env(service).get("LABELMESHD_NATS_URL", "")
            self.require(url == f"nats://{nats[0]}:{NATS_CLIENT_PORT}",
                         f"compose {name}: LABELMESHD_NATS_URL {url!r}")
            self.require(nats[0] in service.get("depends_on", {}),
                         f"compose {name}: does not wait for {nats[0]}")
            directory = env(service).get("LABELMESHD_ARTIFACT_DIR")
            mounted = [v.split(":")[0] for v in service.get("volumes", [])
                       if v.split(":")[1] == directory]
            self.require(mounted and mounted[0] in named_volumes,
                         f"compose {name}: artifact dir {directory!r} is not a named volume")
            artifact_volumes.update(mounted)
        self.require(replicas == {"frontend": 2, "worker": 2},
                     f"compose scaled: {replicas}, not 2 frontends and 2 workers")
        self.require(sorted(host_ports) == ["50051", "50052"],
                     f"compose scaled: frontends on host ports {host_ports}")
        self.require(len(artifact_volumes) == 1,
                     f"compose scaled: artifact volumes {sorted(artifact_volumes)}, not one")


def load_kubernetes(directory):
    """The kustomization and the objects of every file it lists."""
    kustomization = yaml.safe_load((directory / "kustomization.yaml").read_text())
    files = kustomization["resources"]
    problems = [f"{f} is listed in kustomization.yaml but missing" for f in files
                if not (directory / f).is_file()]
    problems += [f"{p.name} is not listed in kustomization.yaml"
                 for p in sorted(directory.glob("*.yaml"))
                 if p.name != "kustomization.yaml" and p.name not in files]
    docs = [d for f in files if (directory / f).is_file()
            for d in yaml.safe_load_all((directory / f).read_text()) if d]
    return kustomization, docs, problems


def known_env(source):
    """LABELMESHD_* names labelmeshd reads, from server/main.cc."""
    text = (source / "server" / "main.cc").read_text()
    return set(re.findall(r'"(LABELMESHD_[A-Z0-9_]+)"', text))


def liveness_service(source):
    """The health service name that answers while labelmeshd serves."""
    text = (source / "server" / "labelmesh_server.h").read_text()
    return re.search(r'kLivenessService\[\] = "([^"]+)"', text).group(1)


def queue_names(source):
    """The job queue's stream and consumer, as labelmeshd declares them."""
    header = source / "server" / "cluster" / "job_queue.h"
    stream, consumer = "LABELMESH_JOBS", "workers"
    if header.is_file():
        text = header.read_text()
        found = re.search(r'std::string stream = "([^"]+)"', text)
        stream = found.group(1) if found else stream
        found = re.search(r'std::string consumer = "([^"]+)"', text)
        consumer = found.group(1) if found else consumer
    return stream, consumer


def find(docs, kind, component):
    return next(d for d in docs if d["kind"] == kind and
                d["metadata"].get("labels", {}).get(COMPONENT) == component)


def container(docs, component):
    kind = "StatefulSet" if component == "nats" else "Deployment"
    return find(docs, kind, component)["spec"]["template"]["spec"]["containers"][0]


def set_env(docs, component, name, value):
    env = container(docs, component)["env"]
    env[:] = [e for e in env if e["name"] != name] + [{"name": name, "value": value}]


def breakages():
    """Broken copies the checks must refuse: (what, how) on (docs, compose)."""
    def k8s(change):
        return lambda docs, compose: change(docs)

    def cmp(change):
        return lambda docs, compose: change(compose["services"])

    return [
        ("worker root file system writable", k8s(lambda d: container(d, "worker")
         ["securityContext"].update(readOnlyRootFilesystem=False))),
        ("NATS may run as root", k8s(lambda d: find(d, "StatefulSet", "nats")["spec"]
         ["template"]["spec"]["securityContext"].pop("runAsNonRoot"))),
        ("frontend without limits", k8s(lambda d: container(d, "frontend")
         ["resources"].pop("limits"))),
        ("worker memory without headroom", k8s(lambda d: container(d, "worker")
         ["resources"]["limits"].update(memory="8Gi"))),
        ("more jobs per worker pod", k8s(lambda d: set_env(d, "worker", "LABELMESHD_WORKERS",
                                                           "3"))),
        ("readiness probe on another port", k8s(lambda d: container(d, "frontend")
         ["readinessProbe"].update(grpc={"port": 50052}))),
        ("liveness on the overall health", k8s(lambda d: container(d, "worker")
         ["livenessProbe"].update(grpc={"port": 50051}))),
        ("grace shorter than the shutdown grace", k8s(lambda d: find(d, "Deployment", "worker")
         ["spec"]["template"]["spec"].update(terminationGracePeriodSeconds=100))),
        ("unknown labelmeshd variable", k8s(lambda d: set_env(
            d, "worker", "LABELMESHD_WORKER_MEMORY", "1"))),
        ("NATS URL to a missing Service", k8s(lambda d: set_env(
            d, "frontend", "LABELMESHD_NATS_URL", "nats://nats:4222"))),
        ("PDB selecting nothing", k8s(lambda d: find(d, "PodDisruptionBudget", "frontend")
         ["spec"]["selector"]["matchLabels"].update({COMPONENT: "frontends"}))),
        ("Service selecting nothing", k8s(lambda d: find(d, "Service", "frontend")
         ["spec"]["selector"].update({COMPONENT: "front"}))),
        ("NATS open to every pod", k8s(lambda d: find(d, "NetworkPolicy", "nats")
         ["spec"]["ingress"][0].pop("from"))),
        ("ScaledObject on another consumer", k8s(lambda d: d[[x["kind"] for x in d].index(
            "ScaledObject")]["spec"]["triggers"][0]["metadata"].update(consumer="worker"))),
        ("artifacts volume ReadWriteOnce", k8s(lambda d: next(
            x for x in d if x["kind"] == "PersistentVolumeClaim")["spec"].update(
                accessModes=["ReadWriteOnce"]))),
        ("compose: one worker", cmp(lambda s: s["worker"]["deploy"].update(replicas=1))),
        ("compose: both frontends on 50051", cmp(lambda s: s["frontend-2"].update(
            ports=["127.0.0.1:50051:50051"]))),
        ("compose: a worker with its own artifacts", cmp(lambda s: s["worker"].update(
            volumes=["spool:/data/artifacts"]))),
        ("compose: labelmeshd in the scaled profile only", cmp(lambda s: s["labelmeshd"].update(
            profiles=["scaled"]))),
    ]


def run(checks, docs, compose, namespace=None):
    checks.problems = []
    checks.kubernetes(docs, namespace)
    checks.compose(compose)
    return checks.problems


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--source-dir", type=pathlib.Path,
                        default=pathlib.Path(__file__).resolve().parents[2])
    args = parser.parse_args()
    source = args.source_dir
    directory = source / "deploy" / "kubernetes"
    kustomization, docs, unlisted = load_kubernetes(directory)
    compose = yaml.safe_load((source / "deploy" / "compose.yaml").read_text())
    checks = Checks(known_env(source), queue_names(source), liveness_service(source))
    passed, failed, details = 0, 0, []

    def report(what, problems):
        nonlocal passed, failed
        if problems:
            failed += 1
            details.extend(f"{what}: {p}" for p in problems)
            print(f"FAIL {what}")
        else:
            passed += 1
            print(f"ok   {what}")

    report("kustomization.yaml lists every file", unlisted)
    report("manifests and compose.yaml", run(checks, docs, compose))
    replaced = [r for r in kustomization.get("replacements", [])
                if r["source"]["fieldPath"] == "metadata.namespace" and
                any(t["select"]["kind"] == "ScaledObject" for t in r["targets"])]
    report("kustomization carries its namespace into the ScaledObject",
           [] if kustomization.get("namespace") and replaced else ["no namespace replacement"])

    kubectl = shutil.which("kubectl")
    if kubectl:
        rendered = subprocess.run([kubectl, "kustomize", str(directory)], capture_output=True,
                                  text=True, timeout=120)
        if rendered.returncode != 0:
            report("kubectl kustomize", [rendered.stderr.strip()])
        else:
            output = [d for d in yaml.safe_load_all(rendered.stdout) if d]
            namespace = kustomization.get("namespace")
            wrong = [f"{d['kind']} {d['metadata']['name']} in {d['metadata'].get('namespace')}"
                     for d in output if d["kind"] != "Namespace" and
                     d["metadata"].get("namespace") != namespace]
            report("kubectl kustomize output", wrong + run(checks, output, compose, namespace))
    else:
        print("skip kubectl kustomize: kubectl is not installed")

    # Each breakage must be refused; the first reason shows which check saw it.
    for what, breakage in breakages():
        broken_docs, broken_compose = copy.deepcopy(docs), copy.deepcopy(compose)
        try:
            breakage(broken_docs, broken_compose)
        except (KeyError, IndexError, StopIteration, ValueError) as error:
            report(f"refuses {what}", [f"cannot break the files this way: {error!r}"])
            continue
        reasons = run(checks, broken_docs, broken_compose)
        report(f"refuses {what}" + (f" ({reasons[0]})" if reasons else ""),
               [] if reasons else ["the checks let it through"])

    for line in details:
        print(f"  {line}")
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
