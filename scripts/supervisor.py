#!/usr/bin/env python3
"""meshnav supervisor: runs the processes of a launch file (python3 standard library only).

Usage: supervisor.py LAUNCH.yaml [VAR=value ...] [--dry-run] [--stop-timeout S]

Launch file (YAML subset: block maps and lists, flow [..] and {..}, quoted strings, # comments):

    name: demo
    stop_timeout: 5          # s between SIGTERM and SIGKILL when stopping (default 5)
    shutdown_after: [imu_bridge, uwb_bridge]  # stop all once these have all exited ...
    shutdown_delay: 2.0      # ... and this many seconds more have passed (default 1)
    t0_margin: 3.0           # ${T0_UTIME} = launch time + this [s] (default 3)
    processes:
      - name: estimator
        command: ${BIN}/estimator          # a path, or a whole command line when args is absent
        args: [--setup, "${DATASET}/setup.yaml"]
        required: true       # when it exits, stop all; a non-zero exit fails the launch
        respawn: false       # restart it whenever it exits (not with required)
        respawn_delay: 1.0   # s before a restart (default 1)
        max_respawns: 10     # give up restarting after this many (default 10; -1 = no limit)
        delay: 0.0           # s after the launch start before this process starts
        env: {MESHNAV_LOG_LEVEL: info}
        cwd: .

${VAR} and ${VAR:-default} in any string are replaced by VAR=value arguments, else the
environment; an unknown variable without default is an error naming it. Built in: ${T0_UTIME},
the wall time [us since the Unix epoch] t0_margin seconds after the launch, so that bridges
started together replay in step (--t0-utime ${T0_UTIME}). Every output line of a
process is printed as "[name] line". SIGINT/SIGTERM stop all processes (SIGTERM to each process
group, SIGKILL after stop_timeout). Exit code: 0 when every required process and every
shutdown_after process exited with 0 (or was stopped cleanly by the supervisor), else 1; 2 for a
bad launch file or arguments.
"""
import os
import re
import shlex
import signal
import subprocess
import sys
import threading
import time


class LaunchError(Exception):
    pass


# ------------------------------------------------------------------------------------ YAML subset

def _strip_comment(s):
    out, quote = [], None
    for i, c in enumerate(s):
        if quote:
            out.append(c)
            if c == quote and not (quote == '"' and i > 0 and s[i - 1] == '\\'):
                quote = None
        elif c in ('"', "'"):
            quote = c
            out.append(c)
        elif c == '#' and (i == 0 or s[i - 1] in ' \t'):
            break
        else:
            out.append(c)
    return ''.join(out).rstrip()


def _convert_plain(s):
    low = s.lower()
    if low in ('true', 'yes', 'on'):
        return True
    if low in ('false', 'no', 'off'):
        return False
    if low in ('null', '~', ''):
        return None
    if re.fullmatch(r'[-+]?\d+', s):
        return int(s)
    if re.fullmatch(r'[-+]?(\d+\.\d*|\.\d+|\d+)([eE][-+]?\d+)?', s):
        return float(s)
    return s


class _Flow:
    """Recursive-descent parser of a flow collection or scalar."""

    def __init__(self, text, where):
        self.s, self.i, self.where = text, 0, where

    def error(self, msg):
        raise LaunchError('%s: %s in %r' % (self.where, msg, self.s))

    def ws(self):
        while self.i < len(self.s) and self.s[self.i] in ' \t':
            self.i += 1

    def value(self, stops):
        self.ws()
        if self.i >= len(self.s):
            return None
        c = self.s[self.i]
        if c == '[':
            self.i += 1
            out = []
            self.ws()
            if self.i < len(self.s) and self.s[self.i] == ']':
                self.i += 1
                return out
            while True:
                out.append(self.value(',]'))
                self.ws()
                if self.i >= len(self.s):
                    self.error('unclosed [')
                if self.s[self.i] == ',':
                    self.i += 1
                    continue
                if self.s[self.i] == ']':
                    self.i += 1
                    return out
                self.error('expected , or ]')
        if c == '{':
            self.i += 1
            out = {}
            self.ws()
            if self.i < len(self.s) and self.s[self.i] == '}':
                self.i += 1
                return out
            while True:
                key = self.value(':,}')
                self.ws()
                if self.i >= len(self.s) or self.s[self.i] != ':':
                    self.error('expected key: value')
                self.i += 1
                out[str(key)] = self.value(',}')
                self.ws()
                if self.i >= len(self.s):
                    self.error('unclosed {')
                if self.s[self.i] == ',':
                    self.i += 1
                    continue
                if self.s[self.i] == '}':
                    self.i += 1
                    return out
                self.error('expected , or }')
        if c in ('"', "'"):
            q = c
            self.i += 1
            buf = []
            while self.i < len(self.s):
                ch = self.s[self.i]
                if q == '"' and ch == '\\' and self.i + 1 < len(self.s):
                    nxt = self.s[self.i + 1]
                    buf.append({'n': '\n', 't': '\t', '"': '"', '\\': '\\'}.get(nxt, '\\' + nxt))
                    self.i += 2
                    continue
                if ch == q:
                    if q == "'" and self.s[self.i + 1:self.i + 2] == "'":
                        buf.append("'")
                        self.i += 2
                        continue
                    self.i += 1
                    return ''.join(buf)
                buf.append(ch)
                self.i += 1
            self.error('unclosed quote')
        start = self.i
        while self.i < len(self.s) and self.s[self.i] not in stops:
            if self.s[self.i] == ':' and ':' in stops and not (
                    self.i + 1 >= len(self.s) or self.s[self.i + 1] in ' \t'):
                self.i += 1  # a colon inside a plain scalar (e.g. udpm://...)
                continue
            self.i += 1
        return _convert_plain(self.s[start:self.i].strip())


def _scalar(text, where):
    p = _Flow(text, where)
    v = p.value('')
    p.ws()
    if p.i != len(text):
        p.error('unexpected text after value')
    return v


def _split_key(text, where):
    """'key: value' -> (key, value text) or None when the line is not a map entry."""
    if text[:1] in ('[', '{'):
        return None
    quote = None
    for i, c in enumerate(text):
        if quote:
            if c == quote:
                quote = None
        elif c in ('"', "'") and i == 0:
            quote = c
        elif c == ':' and (i + 1 == len(text) or text[i + 1] in ' \t'):
            key = _scalar(text[:i].strip(), where)
            return str(key), text[i + 1:].strip()
    return None


def _bracket_depth(s):
    depth, quote = 0, None
    for c in s:
        if quote:
            if c == quote:
                quote = None
        elif c in ('"', "'"):
            quote = c
        elif c in '[{':
            depth += 1
        elif c in ']}':
            depth -= 1
    return depth


def load_yaml_subset(text, source='<launch>'):
    lines = []
    open_flow = None  # a flow collection continued on the next lines
    for n, raw in enumerate(text.splitlines(), 1):
        if '\t' in raw[:len(raw) - len(raw.lstrip())]:
            raise LaunchError('%s:%d: tabs are not allowed for indentation' % (source, n))
        body = _strip_comment(raw)
        if open_flow is not None:
            open_flow[1] += ' ' + body.strip()
            if _bracket_depth(open_flow[1]) <= 0:
                open_flow = None
            continue
        if body.strip() in ('', '---'):
            continue
        lines.append([len(body) - len(body.lstrip(' ')), body.strip(), '%s:%d' % (source, n)])
        if _bracket_depth(body) > 0:
            open_flow = lines[-1]
    if open_flow is not None:
        raise LaunchError('%s: unclosed [ or { at end of file' % open_flow[2])
    if not lines:
        return None
    value, i = _block(lines, 0, lines[0][0])
    if i != len(lines):
        raise LaunchError('%s: unexpected indentation' % lines[i][2])
    return value


def _is_item(text):
    return text == '-' or text.startswith('- ')


def _block(lines, i, indent):
    if _is_item(lines[i][1]):
        return _list(lines, i, indent)
    if _split_key(lines[i][1], lines[i][2]) is None:
        if len(lines) > i + 1 and lines[i + 1][0] > indent:
            raise LaunchError('%s: expected key: value' % lines[i][2])
        return _scalar(lines[i][1], lines[i][2]), i + 1
    return _map(lines, i, indent)


def _list(lines, i, indent):
    out = []
    while i < len(lines) and lines[i][0] == indent and _is_item(lines[i][1]):
        ind, text, where = lines[i]
        rest = text[1:].strip()
        if rest == '':
            if i + 1 < len(lines) and lines[i + 1][0] > indent:
                item, i = _block(lines, i + 1, lines[i + 1][0])
            else:
                item, i = None, i + 1
        elif _is_item(rest) or _split_key(rest, where) is not None:
            col = ind + (len(text) - len(text[1:].lstrip()))
            lines[i] = [col, rest, where]
            item, i = _block(lines, i, col)
        else:
            item, i = _scalar(rest, where), i + 1
        out.append(item)
    return out, i


def _map(lines, i, indent):
    out = {}
    while i < len(lines) and lines[i][0] == indent and not _is_item(lines[i][1]):
        ind, text, where = lines[i]
        kv = _split_key(text, where)
        if kv is None:
            raise LaunchError('%s: expected key: value' % where)
        key, rest = kv
        if key in out:
            raise LaunchError('%s: duplicate key %r' % (where, key))
        if rest:
            out[key], i = _scalar(rest, where), i + 1
        elif i + 1 < len(lines) and lines[i + 1][0] > indent:
            out[key], i = _block(lines, i + 1, lines[i + 1][0])
        elif i + 1 < len(lines) and lines[i + 1][0] == indent and _is_item(lines[i + 1][1]):
            out[key], i = _list(lines, i + 1, indent)
        else:
            out[key], i = None, i + 1
    if i < len(lines) and lines[i][0] > indent:
        raise LaunchError('%s: unexpected indentation' % lines[i][2])
    return out, i


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


def _number(d, key, default, where, kind=float, minimum=0):
    """d[key] (or `default`) as a finite `kind` >= minimum; LaunchError naming `where` and the key."""
    v = d.get(key, default)
    try:
        if isinstance(v, bool):
            raise ValueError
        out = kind(v)
        if not (minimum <= out < float('inf')):
            raise ValueError
    except (TypeError, ValueError, OverflowError):
        raise LaunchError('%s: %s must be a number >= %s, got %r' % (where, key, minimum, v))
    return out


class ProcSpec:
    KEYS = {'name', 'command', 'args', 'required', 'respawn', 'respawn_delay', 'max_respawns',
            'delay', 'env', 'cwd'}

    def __init__(self, d, where):
        if not isinstance(d, dict):
            raise LaunchError('%s: each process must be a map' % where)
        unknown = set(d) - self.KEYS
        if unknown:
            raise LaunchError('%s: unknown process key(s) %s' % (where, ', '.join(sorted(unknown))))
        for k in ('name', 'command'):
            if not d.get(k):
                raise LaunchError('%s: process needs %r' % (where, k))
        self.name = str(d['name'])
        cmd = str(d['command'])
        if d.get('args') is None:
            self.argv = shlex.split(cmd)
        else:
            if not isinstance(d['args'], list):
                raise LaunchError('%s: args of %s must be a list' % (where, self.name))
            self.argv = [cmd] + [_arg_text(a) for a in d['args']]
        self.required = bool(d.get('required', False))
        self.respawn = bool(d.get('respawn', False))
        if self.required and self.respawn:
            raise LaunchError('%s: %s cannot be both required and respawn' % (where, self.name))
        self.respawn_delay = _number(d, 'respawn_delay', 1.0, where)
        self.max_respawns = _number(d, 'max_respawns', 10, where, int, minimum=-1)
        self.delay = _number(d, 'delay', 0.0, where)
        env = d.get('env') or {}
        if not isinstance(env, dict):
            raise LaunchError('%s: env of %s must be a map NAME: value' % (where, self.name))
        self.env = {str(k): '' if v is None else str(v) for k, v in env.items()}
        self.cwd = d.get('cwd')


class Launch:
    KEYS = {'name', 'processes', 'stop_timeout', 'shutdown_after', 'shutdown_delay', 't0_margin'}

    def __init__(self, path, variables):
        try:
            with open(path) as f:
                text = f.read()
        except OSError as e:
            raise LaunchError('%s: %s' % (path, e.strerror))
        except UnicodeDecodeError as e:
            raise LaunchError('%s: not UTF-8 text (byte %d)' % (path, e.start))
        doc = load_yaml_subset(text, path)
        if not isinstance(doc, dict):
            raise LaunchError('%s: expected a map with processes:' % path)
        unknown = set(doc) - self.KEYS
        if unknown:
            raise LaunchError('%s: unknown key(s) %s' % (path, ', '.join(sorted(unknown))))
        # Built-in T0_UTIME: a wall time shortly after the launch [us since the Unix epoch], for
        # bridges that replay in step (--t0-utime ${T0_UTIME}); VAR=value or the environment win.
        margin = _number(doc, 't0_margin', 3.0, path)
        variables = dict(variables)
        variables.setdefault('T0_UTIME', str(int(time.time() * 1e6 + margin * 1e6)))
        doc = substitute(doc, variables, path)
        self.name = str(doc.get('name') or os.path.basename(path))
        self.stop_timeout = _number(doc, 'stop_timeout', 5.0, path)
        self.shutdown_delay = _number(doc, 'shutdown_delay', 1.0, path)
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


# ------------------------------------------------------------------------------------ supervisor

class Supervisor:
    def __init__(self, launch, out=sys.stdout):
        self.launch = launch
        self.out = out
        self.cv = threading.Condition(threading.RLock())
        self.events = []  # (name, exit code) reported by the reader threads
        self.running = {}  # name -> Popen of the current incarnation
        self.alive = set()  # names whose output pump has not reported the exit yet
        self.respawns = {p.name: 0 for p in launch.procs}
        self.final = {}  # name -> last exit code
        self.stopping = False
        self.kill_deadline = None
        self.signal_received = None  # set by the signal handler (only a flag: no locks there)
        self.failed = []

    def say(self, name, line):
        with self.cv:
            self.out.write('[%s] %s\n' % (name, line))
            self.out.flush()

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

    def signal_all(self, sig):
        for p in list(self.running.values()):
            if p.poll() is None:
                try:
                    os.killpg(p.pid, sig)
                except ProcessLookupError:
                    pass

    def stop_all(self, why):
        if self.stopping:
            return
        self.stopping = True
        alive = sorted(n for n, p in self.running.items() if p.poll() is None)
        self.say('supervisor', 'stopping (%s)%s' % (why, ': SIGTERM to ' + ', '.join(alive) if alive else ''))
        self.signal_all(signal.SIGTERM)
        self.kill_deadline = time.monotonic() + self.launch.stop_timeout

    def on_exit(self, name, code, spec):
        desc = ('exit code %d' % code) if code >= 0 else ('signal %d' % -code)
        self.say('supervisor', '%s exited (%s)' % (name, desc))
        if self.stopping:
            # Stopped by us: a clean exit or death by our SIGTERM is fine; SIGKILL is counted below.
            if (spec.required or name in self.launch.shutdown_after) and code not in (0, -signal.SIGTERM, -signal.SIGKILL):
                self.failed.append('%s (%s while stopping)' % (name, desc))
            return None
        if name in self.launch.shutdown_after and code != 0:
            self.failed.append('%s (%s)' % (name, desc))
        if spec.required:
            if code != 0 and name not in self.launch.shutdown_after:
                self.failed.append('%s (%s)' % (name, desc))
            self.stop_all('required process %s exited' % name)
            return None
        if spec.respawn:
            if spec.max_respawns < 0 or self.respawns[name] < spec.max_respawns:
                return time.monotonic() + spec.respawn_delay
            self.say('supervisor', '%s: no more respawns (max_respawns %d)' % (name, spec.max_respawns))
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
                alive = sorted(n for n, p in self.running.items() if p.poll() is None)
                if alive:
                    self.say('supervisor', 'SIGKILL to %s after %.1f s' % (', '.join(alive), self.launch.stop_timeout))
                    self.failed.extend('%s (killed after stop_timeout)' % n for n in alive
                                       if specs[n].required or n in self.launch.shutdown_after)
                    self.signal_all(signal.SIGKILL)
                killed = True
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
            if not self.stopping and self.launch.shutdown_after and shutdown_at is None and \
                    all(n in self.final for n in self.launch.shutdown_after):
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
    args = [a for a in args if a != '--dry-run']
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
    except LaunchError as e:
        print('supervisor: %s' % e, file=sys.stderr)
        return 2
    if stop_timeout is not None:
        launch.stop_timeout = stop_timeout
    if dry_run:
        for p in launch.procs:
            flags = [f for f in ('required', 'respawn') if getattr(p, f)]
            print('%s%s: %s' % (p.name, ' [' + ', '.join(flags) + ']' if flags else '',
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
