#!/usr/bin/env python3
"""meshnav supervisor: runs the processes of a launch file (python3 and PyYAML).

Usage: supervisor.py LAUNCH.yaml [VAR=value ...] [--host NAME] [--list-hosts] [--dry-run] [--stop-timeout S]

Launch file (YAML, read with yaml.safe_load; a key given twice is an error):

    name: demo
    stop_timeout: 5          # s between SIGTERM and SIGKILL when stopping (default 5)
    shutdown_after: [imu_bridge, uwb_bridge]  # stop all once these have all exited for good ...
    shutdown_delay: 2.0      # ... and this many seconds more have passed (default 1)
    stop_last: [logging]     # stopped once every other process has exited (a logger records their last messages)
    t0_margin: 3.0           # ${T0_UTIME} = launch time + this [s] (default 3)
    processes:
      - name: estimator
        command: ${BIN}/estimator          # a path, or a whole command line when args is absent
        args: [--setup, "${DATASET}/setup.yaml"]
        required: true       # when it exits for good (no respawn left), stop all; a non-zero
                             # exit then fails the launch
        respawn: on-failure  # never (false, default) | on-failure (after a non-zero exit or a
                             # signal) | always (true: after any exit)
        respawn_delay: 1.0   # s before the first restart (default 1); doubled after every restart ...
        respawn_delay_max: 30  # ... up to this [s] (default 30)
        max_respawns: 10     # give up restarting after this many (default 10; -1 = no limit)
        delay: 0.0           # s after the launch start before this process starts
        env: {MESHNAV_LOG_LEVEL: info}
        cwd: .
        host: uav            # the machine it runs on (multi-host launch files, docs/deployment.md)

--host NAME starts only the processes whose host: is NAME (run it on each machine, or in each
network namespace of scripts/multihost_netns.sh); shutdown_after then counts only that host's
processes. Without --host every process starts here. --list-hosts prints the host names, one a
line, each followed by "stops" (it has shutdown_after processes: it stops by itself) or "runs" (it
runs until stopped, like a ground station).

${VAR} and ${VAR:-default} in any string are replaced by VAR=value arguments, else the
environment; an unknown variable without default is an error naming it. Built in: ${T0_UTIME},
the wall time [us since the Unix epoch] t0_margin seconds after the launch, so that bridges
started together replay in step (--t0-utime ${T0_UTIME}). Every output line of a
process is printed as "[name] line". SIGINT/SIGTERM stop all processes (SIGTERM to each process
group, SIGKILL after stop_timeout; the stop_last processes get theirs once the others have exited,
so that a logger records what they publish on exit, e.g. the estimator's last POSE_SMOOTHED).
A process that is not required may exit (and exhaust its
respawns) without stopping the others. A process that exits with 7 heard another instance of
itself on the LCM network or found its output folder in use (a second launch): it is never
restarted, and when it is required the launch stops with exit 1. Exit code: 0 when every
required process and every shutdown_after process exited with 0 (or was stopped cleanly by the
supervisor), else 1; 2 for a bad launch file or arguments.
"""
import math
import os
import re
import shlex
import signal
import subprocess
import sys
import threading
import time

import yaml


class LaunchError(Exception):
    pass


# Exit status of a meshnav process that heard another instance of itself publishing its channels
# on the same LCM network right after its start, or found its output folder held by another
# process (transport/process_main.h, kExitSecondInstance): a second launch of the same processes.
# It is never restarted, and a required one stops the launch.
EXIT_SECOND_INSTANCE = 7


# ------------------------------------------------------------------------------------------- YAML

class _StrictLoader(yaml.SafeLoader):
    """yaml.SafeLoader that refuses a key given twice in one map (PyYAML keeps the last one)."""


def _construct_mapping(loader, node, deep=False):
    seen = set()
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if key in seen:
            raise yaml.constructor.ConstructorError(None, None, 'duplicate key %r' % (key,), key_node.start_mark)
        seen.add(key)
    return yaml.SafeLoader.construct_mapping(loader, node, deep=deep)


_StrictLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)


def load_yaml(text, source='<launch>'):
    """The launch document (yaml.safe_load rules, duplicate keys refused). A syntax error is raised
    as LaunchError naming source:line."""
    try:
        return yaml.load(text, Loader=_StrictLoader)
    except yaml.YAMLError as e:
        mark = getattr(e, 'problem_mark', None) or getattr(e, 'context_mark', None)
        where = '%s:%d' % (source, mark.line + 1) if mark is not None else source
        problem = getattr(e, 'problem', None) or str(e)
        raise LaunchError('%s: %s' % (where, problem))


# ----------------------------------------------------------------------------------- launch file

_VAR = re.compile(r'\$\{([A-Za-z_][A-Za-z0-9_]*)(?::-([^}]*))?\}')


def substitute(value, variables, where):
    if isinstance(value, str):
        def repl(m):
            name, default = m.group(1), m.group(2)
            if name in variables:
                return variables[name]
            if default is not None:
                return default
            raise LaunchError('%s: variable ${%s} is not set (give %s=value or set it in the '
                              'environment)' % (where, name, name))
        return _VAR.sub(repl, value)
    if isinstance(value, list):
        return [substitute(v, variables, where) for v in value]
    if isinstance(value, dict):
        return {k: substitute(v, variables, where) for k, v in value.items()}
    return value


def _arg_text(a):
    if a is None:
        return ''
    if isinstance(a, bool):
        return 'true' if a else 'false'
    return str(a)


class ProcSpec:
    KEYS = {'name', 'command', 'args', 'required', 'respawn', 'respawn_delay', 'respawn_delay_max',
            'max_respawns', 'delay', 'env', 'cwd', 'host'}
    RESPAWN = {False: 'never', True: 'always', 'never': 'never', 'always': 'always',
               'on-failure': 'on-failure'}

    def __init__(self, d, where):
        if not isinstance(d, dict):
            raise LaunchError('%s: each process must be a map' % where)
        unknown = set(d) - self.KEYS
        if unknown:
            raise LaunchError('%s: unknown process key(s) %s' % (where, ', '.join(sorted(map(repr, unknown)))))
        for k in ('name', 'command'):
            if not d.get(k):
                raise LaunchError('%s: process needs %r' % (where, k))
        self.name = str(d['name'])
        where = '%s (%s)' % (where, self.name)
        cmd = str(d['command'])
        if d.get('args') is None:
            self.argv = shlex.split(cmd)
        else:
            if not isinstance(d['args'], list):
                raise LaunchError('%s: args must be a list' % where)
            self.argv = [cmd] + [_arg_text(a) for a in d['args']]
        self.required = _flag(d, 'required', where)
        respawn = d.get('respawn', False)
        if not isinstance(respawn, (bool, str)) or respawn not in self.RESPAWN:
            raise LaunchError('%s: respawn must be never, on-failure or always (or false/true), got %r'
                              % (where, respawn))
        self.respawn = self.RESPAWN[respawn]
        self.respawn_delay = _number(d, 'respawn_delay', 1.0, where, minimum=0.0)
        self.respawn_delay_max = _number(d, 'respawn_delay_max', max(30.0, self.respawn_delay), where,
                                         minimum=self.respawn_delay)
        self.max_respawns = int(_number(d, 'max_respawns', 10, where, minimum=-1, integer=True))
        self.delay = _number(d, 'delay', 0.0, where, minimum=0.0)
        env = d.get('env') or {}
        if not isinstance(env, dict):
            raise LaunchError('%s: env must be a map NAME: value' % where)
        self.env = {str(k): '' if v is None else str(v) for k, v in env.items()}
        self.cwd = d.get('cwd')
        host = d.get('host')
        if host is not None and (not isinstance(host, str) or not re.fullmatch(r'[A-Za-z0-9_.-]+', host)):
            raise LaunchError('%s: host must be a name (letters, digits, _ . -), got %r' % (where, host))
        self.host = host

    def restarts_after(self, code):
        """Whether an exit with `code` (negative: killed by that signal) calls for a restart. Never
        after EXIT_SECOND_INSTANCE: another instance runs, a restart would be refused again."""
        if code == EXIT_SECOND_INSTANCE:
            return False
        return self.respawn == 'always' or (self.respawn == 'on-failure' and code != 0)

    def respawn_wait(self, n):
        """Seconds before restart number n + 1 (n = restarts so far): doubling, capped."""
        return min(self.respawn_delay * (2.0 ** n), self.respawn_delay_max)


def _flag(d, key, where):
    v = d.get(key, False)
    if not isinstance(v, bool):
        raise LaunchError('%s: %s must be true or false, got %r' % (where, key, v))
    return v


def _number(d, key, default, where, minimum, integer=False):
    v = d.get(key, default)
    if isinstance(v, str):  # a number from a ${VAR} ("respawn_delay: ${DELAY:-0.2}")
        try:
            v = int(v) if integer else float(v)
        except ValueError:
            pass
    ok = isinstance(v, int) if integer else isinstance(v, (int, float))
    if isinstance(v, bool) or not ok or not math.isfinite(v) or v < minimum:
        raise LaunchError('%s: %s must be %s >= %s, got %r' % (where, key, 'an integer' if integer else 'a number',
                                                               minimum, v))
    return v


class Launch:
    KEYS = {'name', 'processes', 'stop_timeout', 'shutdown_after', 'shutdown_delay', 't0_margin', 'stop_last'}

    def __init__(self, path, variables):
        try:
            with open(path) as f:
                text = f.read()
        except OSError as e:
            raise LaunchError('%s: %s' % (path, e.strerror))
        except UnicodeDecodeError as e:
            raise LaunchError('%s: not UTF-8 text (byte %d)' % (path, e.start))
        doc = load_yaml(text, path)
        if not isinstance(doc, dict):
            raise LaunchError('%s: expected a map with processes:' % path)
        unknown = set(doc) - self.KEYS
        if unknown:
            # repr: YAML keys need not be strings (`yes:` is a bool, `1:` an int)
            raise LaunchError('%s: unknown key(s) %s' % (path, ', '.join(sorted(map(repr, unknown)))))
        # Built-in T0_UTIME: a wall time shortly after the launch [us since the Unix epoch], for
        # bridges that replay in step (--t0-utime ${T0_UTIME}); VAR=value or the environment win.
        margin = _number(doc, 't0_margin', 3.0, path, minimum=0.0)
        variables = dict(variables)
        variables.setdefault('T0_UTIME', str(int(time.time() * 1e6 + margin * 1e6)))
        doc = substitute(doc, variables, path)
        self.name = str(doc.get('name') or os.path.basename(path))
        self.stop_timeout = _number(doc, 'stop_timeout', 5.0, path, minimum=0.0)
        self.shutdown_delay = _number(doc, 'shutdown_delay', 1.0, path, minimum=0.0)
        procs = doc.get('processes')
        if not isinstance(procs, list) or not procs:
            raise LaunchError('%s: processes: must be a non-empty list' % path)
        self.procs = [ProcSpec(p, '%s: processes[%d]' % (path, i)) for i, p in enumerate(procs)]
        names = [p.name for p in self.procs]
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise LaunchError('%s: duplicate process name(s) %s' % (path, ', '.join(sorted(dup))))
        self.shutdown_after = [str(n) for n in (doc.get('shutdown_after') or [])]
        for n in self.shutdown_after:
            if n not in names:
                raise LaunchError('%s: shutdown_after names unknown process %r' % (path, n))
        self.stop_last = [str(n) for n in (doc.get('stop_last') or [])]
        for n in self.stop_last:
            if n not in names:
                raise LaunchError('%s: stop_last names unknown process %r' % (path, n))
        self.path = path

    def hosts(self):
        """Host names in the order of their first process."""
        out = []
        for p in self.procs:
            if p.host is not None and p.host not in out:
                out.append(p.host)
        return out

    def select_host(self, host):
        """Keeps only the processes of `host` (shutdown_after likewise)."""
        if host not in self.hosts():
            raise LaunchError('%s: no process has host %r (hosts: %s)' % (self.path, host,
                                                                          ', '.join(self.hosts()) or 'none'))
        self.procs = [p for p in self.procs if p.host == host]
        names = {p.name for p in self.procs}
        self.shutdown_after = [n for n in self.shutdown_after if n in names]
        self.name = '%s@%s' % (self.name, host)


# ------------------------------------------------------------------------------------ supervisor

class Supervisor:
    def __init__(self, launch, out=sys.stdout):
        self.launch = launch
        self.out = out
        self.output_lost = False
        try:
            self.out_fd = out.fileno()
        except (AttributeError, OSError, ValueError):
            self.out_fd = None
        self.cv = threading.Condition(threading.RLock())
        self.events = []  # (name, exit code) reported by the reader threads
        self.running = {}  # name -> Popen of the current incarnation
        self.alive = set()  # names whose output pump has not reported the exit yet
        self.respawns = {p.name: 0 for p in launch.procs}
        self.final = {}  # name -> last exit code
        self.gone = set()  # names that exited for good (no respawn)
        self.stopping = False
        self.last_pending = False  # stop_last processes wait for the others to exit
        self.kill_deadline = None
        self.signal_received = None  # set by the signal handler (only a flag: no locks there)
        self.failed = []

    def say(self, name, line):
        """Writes one prefixed line. Its own output never stops the supervision (issue 36): when
        stdout is gone (a reader like `head` closed the pipe, the disk is full) the lines are
        dropped from then on, said once on stderr, and the processes are still watched, their
        exits handled and the run's exit code kept."""
        with self.cv:
            if self.out is None:
                return
            try:
                self.out.write('[%s] %s\n' % (name, line))
                self.out.flush()
            except (OSError, ValueError) as e:  # BrokenPipeError, ENOSPC, a closed stream
                self.out = None
                self.output_lost = True
                try:
                    # Python would fail flushing the broken stdout again at exit: point it at /dev/null.
                    if self.out_fd is not None:
                        devnull = os.open(os.devnull, os.O_WRONLY)
                        os.dup2(devnull, self.out_fd)
                        os.close(devnull)
                    sys.stderr.write('supervisor: output lost (%s); still supervising\n' % e)
                    sys.stderr.flush()
                except OSError:
                    pass

    def start(self, spec):
        env = dict(os.environ)
        env.update(spec.env)
        try:
            p = subprocess.Popen(spec.argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                 stdin=subprocess.DEVNULL, env=env, cwd=spec.cwd,
                                 start_new_session=True)
        except OSError as e:
            self.say('supervisor', 'cannot start %s (%s): %s' % (spec.name, spec.argv[0], e.strerror))
            with self.cv:
                self.alive.add(spec.name)
                self.events.append((spec.name, 127))
            return
        with self.cv:
            self.running[spec.name] = p
            self.alive.add(spec.name)
        self.say('supervisor', 'started %s (pid %d): %s' % (spec.name, p.pid, ' '.join(
            shlex.quote(a) for a in spec.argv)))
        threading.Thread(target=self._pump, args=(spec.name, p), daemon=True).start()

    def _pump(self, name, p):
        for raw in iter(p.stdout.readline, b''):
            self.say(name, raw.decode('utf-8', 'replace').rstrip('\n'))
        code = p.wait()
        with self.cv:
            self.events.append((name, code))
            self.cv.notify_all()

    def signal_all(self, sig, names=None):
        for name, p in list(self.running.items()):
            if (names is None or name in names) and p.poll() is None:
                try:
                    os.killpg(p.pid, sig)
                except ProcessLookupError:
                    pass

    def stop_all(self, why):
        if self.stopping:
            return
        self.stopping = True
        alive = sorted(n for n, p in self.running.items() if p.poll() is None)
        first = [n for n in alive if n not in self.launch.stop_last]
        # stop_last (a logger): signalled once the others have exited, so it records what they
        # publish on their way out (run_stop_last).
        self.last_pending = bool(first) and any(n in self.launch.stop_last for n in alive)
        now_stopped = first if self.last_pending else alive
        self.say('supervisor', 'stopping (%s)%s' % (why, ': SIGTERM to ' + ', '.join(now_stopped) if now_stopped else ''))
        self.signal_all(signal.SIGTERM, set(now_stopped))
        self.kill_deadline = time.monotonic() + self.launch.stop_timeout

    def stop_last_when_alone(self):
        """While stopping: SIGTERM to the stop_last processes once every other one has exited."""
        if not self.last_pending:
            return
        if any(n not in self.launch.stop_last and p.poll() is None for n, p in self.running.items()):
            return
        self.last_pending = False
        last = sorted(n for n, p in self.running.items() if n in self.launch.stop_last and p.poll() is None)
        if last:
            self.say('supervisor', 'SIGTERM to %s (stop_last: the others have exited)' % ', '.join(last))
            self.signal_all(signal.SIGTERM, set(last))
            self.kill_deadline = time.monotonic() + self.launch.stop_timeout

    def on_exit(self, name, code, spec):
        """Handles one exit; returns the monotonic time of the restart, or None when the process
        has exited for good (then it counts for required / shutdown_after)."""
        desc = ('exit code %d' % code) if code >= 0 else ('signal %d' % -code)
        self.say('supervisor', '%s exited (%s)' % (name, desc))
        if code == EXIT_SECOND_INSTANCE and not self.stopping:
            desc = 'another instance already runs on this LCM network or writes its folder: a second launch?'
            self.say('supervisor', '%s refused to run: %s Stop the other launch, or give this one another LCM URL '
                     '(LCM_DEFAULT_URL) and output folder; not restarted' % (name, desc))
        if self.stopping:
            # Stopped by us: a clean exit or death by our SIGTERM is fine; SIGKILL is counted below.
            if (spec.required or name in self.launch.shutdown_after) and code not in (0, -signal.SIGTERM, -signal.SIGKILL):
                self.failed.append('%s (%s while stopping)' % (name, desc))
            return None
        if spec.restarts_after(code):
            n = self.respawns[name]
            if spec.max_respawns < 0 or n < spec.max_respawns:
                wait = spec.respawn_wait(n)
                self.say('supervisor', 'restarting %s in %.2f s' % (name, wait))
                return time.monotonic() + wait
            self.say('supervisor', '%s: no more respawns (max_respawns %d)' % (name, spec.max_respawns))
        self.gone.add(name)
        if name in self.launch.shutdown_after and code != 0:
            self.failed.append('%s (%s)' % (name, desc))
        if spec.required:
            if code != 0 and name not in self.launch.shutdown_after:
                self.failed.append('%s (%s)' % (name, desc))
            self.stop_all('required process %s exited' % name)
        return None

    def run(self):
        specs = {p.name: p for p in self.launch.procs}
        t0 = time.monotonic()
        pending = sorted(self.launch.procs, key=lambda s: s.delay)  # stable: file order for equal delays
        respawn_at = {}  # name -> monotonic time
        shutdown_at = None
        killed = False
        while True:
            if self.signal_received is not None and not self.stopping:
                self.stop_all('signal %d' % self.signal_received)
            now = time.monotonic()
            if not self.stopping:
                while pending and now - t0 >= pending[0].delay:
                    self.start(pending.pop(0))
                for name, when in list(respawn_at.items()):
                    if now >= when:
                        del respawn_at[name]
                        self.respawns[name] += 1
                        self.say('supervisor', 'respawning %s (%d)' % (name, self.respawns[name]))
                        self.start(specs[name])
                if shutdown_at is not None and now >= shutdown_at:
                    self.stop_all('every shutdown_after process has exited')
            elif not killed and now >= self.kill_deadline:
                # The processes signalled last (all, or the first ones while stop_last waits).
                alive = sorted(n for n, p in self.running.items() if p.poll() is None and
                               (not self.last_pending or n not in self.launch.stop_last))
                if alive:
                    self.say('supervisor', 'SIGKILL to %s after %.1f s' % (', '.join(alive), self.launch.stop_timeout))
                    self.failed.extend('%s (killed after stop_timeout)' % n for n in alive
                                       if specs[n].required or n in self.launch.shutdown_after)
                    self.signal_all(signal.SIGKILL, set(alive))
                # With stop_last still waiting, its SIGTERM comes once the killed ones are reaped
                # (stop_last_when_alone, with a deadline of its own).
                killed = not self.last_pending
                if self.last_pending:
                    self.kill_deadline = now + self.launch.stop_timeout
            with self.cv:
                if not self.events:
                    self.cv.wait(timeout=0.1)
                events, self.events = self.events, []
            for name, code in events:
                self.alive.discard(name)
                self.final[name] = code
                when = self.on_exit(name, code, specs[name])
                if when is not None:
                    respawn_at[name] = when
            if self.stopping:
                self.stop_last_when_alone()
            if not self.stopping and self.launch.shutdown_after and shutdown_at is None and \
                    all(n in self.gone for n in self.launch.shutdown_after):
                shutdown_at = time.monotonic() + self.launch.shutdown_delay
            with self.cv:
                idle = not self.alive and not self.events
            if idle and (self.stopping or (not pending and not respawn_at)):
                break  # everything has exited (or nothing is left to supervise)
        if self.failed:
            self.say('supervisor', 'FAILED: ' + ', '.join(self.failed))
            return 1
        self.say('supervisor', 'done')
        return 0


def main(argv):
    args = argv[1:]
    if not args or args[0] in ('-h', '--help'):
        print(__doc__)
        return 0 if args else 2
    dry_run = '--dry-run' in args
    list_hosts = '--list-hosts' in args
    args = [a for a in args if a not in ('--dry-run', '--list-hosts')]
    host = None
    if '--host' in args:
        i = args.index('--host')
        if i + 1 >= len(args) or args[i + 1].startswith('-') or '=' in args[i + 1]:
            print('supervisor: --host needs a host name', file=sys.stderr)
            return 2
        host = args[i + 1]
        del args[i:i + 2]
    if not args:
        print('supervisor: no launch file given', file=sys.stderr)
        return 2
    stop_timeout = None
    if '--stop-timeout' in args:
        i = args.index('--stop-timeout')
        try:
            stop_timeout = float(args[i + 1])
        except (IndexError, ValueError):
            print('supervisor: --stop-timeout needs seconds', file=sys.stderr)
            return 2
        del args[i:i + 2]
    launch_path, rest = args[0], args[1:]
    variables = dict(os.environ)
    for a in rest:
        if '=' not in a or a.startswith('-'):
            print('supervisor: unexpected argument %r (expected VAR=value)' % a, file=sys.stderr)
            return 2
        k, v = a.split('=', 1)
        variables[k] = v
    try:
        launch = Launch(launch_path, variables)
        if list_hosts:
            for h in launch.hosts():
                stops = any(p.host == h and p.name in launch.shutdown_after for p in launch.procs)
                print('%s %s' % (h, 'stops' if stops else 'runs'))
            return 0
        if host is not None:
            launch.select_host(host)
    except LaunchError as e:
        print('supervisor: %s' % e, file=sys.stderr)
        return 2
    if stop_timeout is not None:
        launch.stop_timeout = stop_timeout
    if dry_run:
        for p in launch.procs:
            flags = (['required'] if p.required else []) + (['respawn ' + p.respawn] if p.respawn != 'never' else [])
            print('%s%s%s: %s' % (p.name, '@' + p.host if p.host else '', ' [' + ', '.join(flags) + ']' if flags else '',
                                ' '.join(shlex.quote(a) for a in p.argv)))
        return 0
    sup = Supervisor(launch)

    def on_signal(signum, frame):
        sup.signal_received = signum

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    sup.say('supervisor', 'launch %s: %d processes' % (launch.name, len(launch.procs)))
    return sup.run()


if __name__ == '__main__':
    sys.exit(main(sys.argv))
