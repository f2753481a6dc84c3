"""FMU import: an FMI 2.0 or 3.0 co-simulation or model-exchange FMU, or an FMI 3.0
scheduled-execution FMU, as a block, through fmpy's low-level API.

In a diagram::

    blocks:
      plant:
        type: FMU
        period: 10 ms                          # the interval between the hits (default: the FMU's step)
        params:
          path: fmus/first_order.fmu           # relative to the diagram's folder
          start_values: {a: 0.9, "z[2]": 1.0, gains: [1, 2, 3]}
      ball:
        type: FMU
        period: 10 ms
        params: {path: fmus/BouncingBall.fmu, interface: model_exchange,  # the default for an ME-only FMU
                 solver: cvode, tolerance: 1e-6}                          # or solver: euler, substep: 1 ms
    connections:
      - ctrl.y -> plant.u
      - plant.y -> ctrl.u

Ports. Every input variable (causality ``input``) and output variable (causality
``output``) of a numeric type becomes a float64 port: Real, Integer, Enumeration and
Boolean (FMI 2); Float64, Float32, Int8 ... UInt64, Enumeration and Boolean (FMI 3). An
integer reaches the port exactly (a 64-bit one up to 2^53; a larger value stops the run
with a BlockError rather than change), a Boolean as 0 or 1; an integer input takes whole
numbers in its type's range and a Boolean input 0 or 1, anything else stops the run
naming the port, value and time. ``port_types`` records each port's FMI type (in FMI 3
names: FMI 2's Real is Float64, its Integer Int32), so ``validate`` lists connections
between different types with their rules. Scalars named ``x[1]``, ``x[2]``, ... (and
``A[1,1]``, ``A[1,2]``, ... row-major) form one vector port ``x``; an FMI 3 array variable
is one port of its flattened size; ``element_labels`` keeps the FMU's indices for the CSV
columns, and ``port_units`` the variables' units (their ``unit`` or their declared
type's). The indices must start at 1 and have no gaps. Port names are the variable (or
vector) names with every character other than letters, digits and ``_`` replaced by
``_`` (``body.v[2]`` -> port ``body_v``). FMI 3 ``<Alias>`` outputs are ports of their own.
String, Binary and Clock variables are not ports (``port_hint`` says so when a diagram
names one), except a scheduled-execution FMU's triggered input clocks and output clocks;
give String inputs values with ``start_values``.

Interface. An FMU offering co-simulation runs as co-simulation, one offering only model
exchange as model exchange; ``interface: model_exchange`` (or ``co_simulation``) chooses.
One offering only scheduled execution has its input clocks activated at the block's hits
(``scheduled``: periodic, triggered and countdown clocks, in priority order).

Semantics. ``output(t)`` returns the FMU outputs at the hit ``t`` and ``update(t)`` sets
the inputs seen at ``t`` and steps the FMU to the next hit ``t + period``, so inputs are
held over each step (zero-order hold). The exchange at a hit is ordered by the
dependencies the FMU declares (its ModelStructure Outputs; an output without a
``dependencies`` attribute depends on every input), as OMSimulator orders it: a co-simulation FMU's outputs that
depend on inputs are read after that hit's inputs are set, before the blocks downstream
read them (``feedthrough``, per output port), so the planner evaluates a chain through the
FMU in order and a loop through those dependencies is an algebraic loop (a load error
naming the port chain). Outputs that depend on no input, every output of a block with
``feedthrough: false`` (the Jacobi scheme, as libcosim's master steps) and every output of
a model-exchange FMU come from the end of the previous step, so they never depend on the
input of the same instant. The first output, at the block's first hit ``t0`` (its
offset), is the FMU's initial output after initialisation with start time ``t0``, with the
inputs set before initialisation ends, as in FMPy. At t = 0 the blocks feeding the inputs
the FMU's initial outputs depend on (its InitialUnknowns) are computed first
(``initial_feedthrough``), unless that closes a loop, in which case the input keeps its
start value there.

Co-simulation. A step is ``doStep(t, period)``. The FMU's step rules are its own: a
``fixedInternalStepSize`` is informative (``validate`` shows it); an FMU that says it
cannot vary its communication step (``canHandleVariableCommunicationStepSize`` false)
takes only the step it declares (its DefaultExperiment stepSize, else its fixed internal
step), so another period is refused at load time; a step the FMU refuses at run time (an
error status) fails the run with its message.

Model exchange (``exchange``, ``solvers``). The block integrates the model from hit to
hit with ``solver: cvode`` (SUNDIALS' CVode as fmpy ships it: BDF, relative
``tolerance``, root finding on the event indicators) or ``solver: euler`` (forward Euler
with a fixed ``substep`` that divides the period; state events located by bisection to
``tolerance`` times the sub-step). Defaults: the DefaultExperiment's tolerance (else
1e-5) and stepSize (made to divide the period; else the period). As fmpy's ME simulation
does, it handles time events (nextEventTime), state events (an event indicator changing
sign) and step events (completedIntegratorStep), each with event mode and event
iteration, and restarts the solver after each; inputs that changed at a hit are set in
event mode too (an external event). Outputs are read at the hits, after any event there.

Termination. An FMU that asks to end the simulation (FMI 2: ``fmi2Discard`` with
``fmi2Terminated``; FMI 3: ``terminateSimulation``; in model exchange, terminateSimulation
from event iteration or completedIntegratorStep) ends the run with ``EndRun``: the run is
complete and stops at the end of that step, where the FMU's outputs are those it reached
(at ``lastSuccessfulTime``, or the time of the request). A discard without that request,
an early return or an error status is a failure.

Loading and running. Loading a diagram reads only the archive's member list and its
modelDescription.xml (``description.read_description``): ``hierhand validate`` and ``graph``
never run an FMU's code. The archive is extracted and the binary loaded when a run first
needs an instance, at the block's first ``output`` or ``update``.

Isolation. Each instance runs in a process of its own (``isolation: process``, the default
except for the FMUs this project exports, recognised by their ``generationTool``), so that
a crash, an ``exit()`` or a hang in the FMU's code fails the run instead of ending it: the
host process (``host``) is forked by one launcher per process (``launcher``) and answers
the block through a channel (``channel``: shared memory, one round trip per steady step,
and messages for the rest), which ``hosted.HostedInstance`` drives with the surface of an
in-process instance; the block and its kernel use either the same way. A call that does
not return within ``call_timeout`` kills the host. ``isolation: none`` runs the instance in
the run's process, the fastest.

State. The FMU instance is external mutable state: ``initial_state()`` hands each run its
own ``FMUState``, which takes an instance from the block's pool (reset), or instantiates
one if every pooled one is in use, at the run's first call. When the run's state is
garbage collected (or ``close()``d) the instance is terminated and returned to the pool;
instances are freed when the block goes away, at process exit, or by ``FMU.close()``. An
instance that failed is freed, never reused. The state cannot be copied or checkpointed
(FMU get/set state is not used).

Errors. Problems with the file (missing, not a regular file, unreadable), its
modelDescription (steps out of range, arrays too large), the parameters and a period the
FMU cannot step are raised at load time (ValueError, which the diagram loader reports as
``file:line: block 'x' (FMU): ...``). A binary that does not load or instantiate, a
failing ``doStep`` or model-exchange call, and a failing solver raise ``BlockError``
naming the FMU, the function, the time and the status, with the FMU's recent log
messages; so does an isolated FMU whose process ended inside a call (the signal or exit
code) or that did not return in time (``hosted.HostFailure``). The executor keeps the
results up to that point. Ctrl-C inside an FMU call or
the integration is a KeyboardInterrupt, never an FMU failure (see ``interrupt``).

Modules, one concept each:

- ``block``: the FMU block and its run state ``FMUState``;
- ``model``: what the modelDescription says, checked when the block is made;
- ``port_types``: the FMI types that become ports and how their values travel as float64;
- ``ports``: variables grouped into ports, element labels, initial dependencies;
- ``start_values``: what start values may set, their conversion and checks;
- ``pool``: the instances of one FMU, reused across runs;
- ``instance``: one FMU instance with its preallocated value transfers, FMI 2 and 3;
- ``cosimulation``: a co-simulation instance's step (doStep and what its status says);
- ``exchange``: a model-exchange instance's step (integration, events, event iteration);
- ``solvers``: the integration settings, CVode and Euler over the C loops of blocks/csrc/fmu_me_integration.c;
- ``sundials``: the SUNDIALS (CVode) functions of fmpy's libraries, declared for ``solvers``;
- ``kernel``: the compiled steady step (blocks/csrc/fmu_block_step.c) of a co-simulation FMU with Float64 ports
  only (in this process, or through the channel of an isolated instance);
- ``hosted``: an instance in a process of its own, as the run sees it; ``host``: that process;
  ``channel``: the shared memory and messages between them (blocks/csrc/fmu_channel.c);
  ``launcher``: the process that forks the hosts, as the run sees it; ``forkserver``: that process;
- ``native``: the compiled functions of blocks._native the FMU modules use;
- ``log_messages``: the FMUs' log messages and the FMI 2 logger proxy;
- ``interrupt``: Ctrl-C inside FMU calls;
- ``description``: reading a modelDescription without running code (``hierhand fmu info``);
- ``archive``: safe reading and extraction of FMU archives.
"""

from .archive import ArchiveError, Limits, extract_archive, read_member
from .block import FMU, FMUState
from .description import FMUDescription, FMUInfoError, describe_fmu, read_description

__all__ = [
    "FMU", "ArchiveError", "FMUDescription", "FMUInfoError", "FMUState", "Limits", "describe_fmu",
    "extract_archive", "read_description", "read_member",
]
