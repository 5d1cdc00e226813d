#!/usr/bin/python3
# The [DISPLAY] program of the configuration tools/linuxcnc/run writes: instead of a GUI it
# drives LinuxCNC through the `linuxcnc` Python module. It resets the estop, switches the
# machine on, homes all joints (instantly, simulated), moves by MDI G0 to the program's first
# point, starts halsampler and enables the sampler, runs the program to its end, stops the
# sampler and exits, which shuts LinuxCNC down. Environment (set by `run`):
#   LCNC_PROGRAM  the G-code file (absolute path)
#   LCNC_RAW      where halsampler's output goes
#   LCNC_STATUS   a file that receives "OK ..." or "FAIL reason" at the end
#   LCNC_START    the MDI G0 words for the program's first point (may be empty)
#   LCNC_TIMEOUT  seconds the program may run (default 3600)
import os, subprocess, sys, time
import linuxcnc

PROGRAM = os.environ["LCNC_PROGRAM"]
RAW = os.environ["LCNC_RAW"]
STATUS = os.environ["LCNC_STATUS"]
START = os.environ.get("LCNC_START", "").strip()
TIMEOUT = float(os.environ.get("LCNC_TIMEOUT", "3600"))

s = linuxcnc.stat()
c = linuxcnc.command()
e = linuxcnc.error_channel()
sampler = None


def log(msg):
    print("driver: " + msg, file=sys.stderr, flush=True)


def halcmd(*args):
    r = subprocess.run(["halcmd"] + list(args), capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError("halcmd %s: %s" % (" ".join(args), r.stderr.strip()))
    return r.stdout.strip()


def finish(ok, msg):
    try:
        halcmd("setp", "sampler.0.enable", "0")
    except Exception:
        pass
    if sampler is not None and sampler.poll() is None:
        sampler.terminate()
        sampler.wait(10)
    with open(STATUS, "w") as f:
        f.write(("OK " if ok else "FAIL ") + msg + "\n")
    log(("done: " if ok else "FAILED: ") + msg)
    try:  # leave the machine in estop; the linuxcnc script then shuts everything down
        c.state(linuxcnc.STATE_ESTOP)
    except Exception:
        pass
    sys.exit(0 if ok else 1)


def check_errors():
    while True:
        m = e.poll()
        if not m:
            return
        kind, text = m
        if kind in (linuxcnc.NML_ERROR, linuxcnc.OPERATOR_ERROR):
            finish(False, "LinuxCNC error: %s" % text)
        log("message: %s" % text)


def wait_for(cond, what, timeout=30.0):
    t0 = time.time()
    while True:
        s.poll()
        check_errors()
        if cond():
            return
        if time.time() - t0 > timeout:
            finish(False, "timed out waiting for " + what)
        time.sleep(0.005)


def wait_interp_idle(what, timeout):
    # the interpreter may not have left idle yet right after a command: see it busy or wait 0.5 s
    t0 = time.time()
    seen_busy = False
    while True:
        s.poll()
        check_errors()
        if s.task_state != linuxcnc.STATE_ON:
            finish(False, "machine left the ON state during %s (estop or fault)" % what)
        if s.interp_state != linuxcnc.INTERP_IDLE:
            seen_busy = True
        elif (seen_busy or time.time() - t0 > 0.5) and s.queue == 0 and s.inpos:
            return
        if time.time() - t0 > timeout:
            finish(False, "timed out during " + what)
        time.sleep(0.002)


try:
    wait_for(lambda: True, "the status channel")
    c.state(linuxcnc.STATE_ESTOP_RESET)
    wait_for(lambda: s.task_state == linuxcnc.STATE_ESTOP_RESET, "estop reset")
    c.state(linuxcnc.STATE_ON)
    wait_for(lambda: s.task_state == linuxcnc.STATE_ON, "machine on")
    c.mode(linuxcnc.MODE_MANUAL)
    c.wait_complete()
    c.teleop_enable(0)
    c.wait_complete()
    c.home(-1)
    wait_for(lambda: all(s.homed[j] for j in range(s.joints)), "homing")
    c.mode(linuxcnc.MODE_MDI)
    c.wait_complete()
    if START:
        log("MDI G0 " + START)
        c.mdi("G0 " + START)
        wait_interp_idle("the move to the start", 120)

    # record from here on
    sampler = subprocess.Popen(["stdbuf", "-oL", "halsampler", "-t"],
                               stdout=open(RAW, "w"), stderr=subprocess.PIPE)
    time.sleep(0.3)
    if sampler.poll() is not None:
        finish(False, "halsampler exited: %s" % sampler.stderr.read().decode())
    halcmd("setp", "sampler.0.overruns", "0")
    halcmd("setp", "sampler.0.sample-num", "0")
    halcmd("setp", "sampler.0.enable", "1")

    c.mode(linuxcnc.MODE_AUTO)
    c.wait_complete()
    c.program_open(PROGRAM)
    c.wait_complete()
    t0 = time.time()
    c.auto(linuxcnc.AUTO_RUN, 0)
    wait_interp_idle("the program", TIMEOUT)
    log("program finished after %.1f s wall time" % (time.time() - t0))
    time.sleep(0.2)  # a few idle periods at the end
    halcmd("setp", "sampler.0.enable", "0")
    overruns = int(halcmd("getp", "sampler.0.overruns"))
    # let halsampler empty the FIFO, then stop it
    t1 = time.time()
    while int(halcmd("getp", "sampler.0.curr-depth")) > 0 and time.time() - t1 < 60:
        time.sleep(0.05)
    time.sleep(0.3)
    sampler.terminate()
    sampler.wait(10)
    if overruns:
        finish(False, "sampler FIFO overran %d times: samples lost" % overruns)
    finish(True, "sampler overruns=0")
except SystemExit:
    raise
except Exception as ex:
    finish(False, "driver exception: %r" % (ex,))
