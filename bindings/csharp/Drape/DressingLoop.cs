using System;

namespace Drape
{
    /// <summary>Which time step <see cref="DressingLoop.Tick"/> gives <see cref="Context.Step"/>.</summary>
    public enum StepTiming
    {
        /// <summary>The host's frame time (Unity's <c>Time.deltaTime</c>), every tick, also between
        /// sensor frames: the cloth keeps moving at the display rate.</summary>
        HostDelta = 0,
        /// <summary>Only when a new frame was accepted, by the difference of its timestamp and the
        /// previous accepted frame's (the first frame: <see cref="DressingLoop.FirstFrameDtS"/>),
        /// clamped to [1e-6, 10] s. What the native drape-replay does: with a
        /// <see cref="RecordingJointSource"/> in <see cref="PlaybackMode.EveryCall"/> the loop gives
        /// the same vertices as drape-replay.</summary>
        SourceTimestamps = 1,
    }

    /// <summary>
    /// The per-frame driver for a host: takes frames from an <see cref="IJointSource"/>, pushes them
    /// into a <see cref="Context"/> and steps the body and its garments. A Unity MonoBehaviour calls
    /// <see cref="Tick"/> from <c>Update()</c> and then reads meshes (<see cref="MeshSpace"/>).
    /// <para>A frame the library rejects (NaN joints, a timestamp not after the previous one, ...)
    /// is counted in <see cref="RejectedFrames"/> and kept in <see cref="LastRejection"/>; the loop
    /// goes on. Other failures throw. No managed allocation per tick in the steady state (a
    /// rejection allocates its exception). Same threading rule as <see cref="Context"/>.</para>
    /// </summary>
    public sealed class DressingLoop : IDisposable
    {
        private readonly Context _context;
        private readonly IJointSource _source;
        private readonly bool _ownsSource;
        private readonly Joint[] _joints;
        private readonly Layout _layout;
        private bool _accepted;         // a frame was ever accepted (Step is legal from then on)
        private bool _havePrevious;
        private double _previousTimestamp;
        private double _firstFrameDt = 1.0 / 30.0;

        /// <summary>A loop over a new context with the default settings.</summary>
        public DressingLoop(IJointSource source, bool ownsSource = false)
            : this(source, ContextDesc.CreateDefault(), ownsSource)
        {
        }

        /// <summary>A loop over a new context made with <paramref name="desc"/>. With
        /// <paramref name="ownsSource"/>, <see cref="Dispose"/> disposes the source if it is
        /// <see cref="IDisposable"/>.</summary>
        public DressingLoop(IJointSource source, in ContextDesc desc, bool ownsSource = false)
        {
            _source = source ?? throw new ArgumentNullException(nameof(source));
            _layout = source.Layout;
            int count = source.JointCount;
            if (_layout == Layout.Auto || count <= 0)
                throw new ArgumentException($"the joint source must name a layout (not Auto) and a joint count > 0 " +
                                            $"(it says {_layout}, {count})", nameof(source));
            _joints = new Joint[count];
            _context = new Context(desc);
            _ownsSource = ownsSource;
            if (source is RecordingJointSource rec) _firstFrameDt = rec.FramePeriodS;
        }

        /// <summary>The context: add garments to it, set the body shape, read statistics.</summary>
        public Context Context => _context;

        /// <summary>The joint source.</summary>
        public IJointSource Source => _source;

        /// <summary>See <see cref="StepTiming"/>. Default <see cref="StepTiming.HostDelta"/>.</summary>
        public StepTiming Timing { get; set; } = StepTiming.HostDelta;

        /// <summary>The step of the first accepted frame under <see cref="StepTiming.SourceTimestamps"/>:
        /// one nominal frame period of a <see cref="RecordingJointSource"/>, else 1/30 s.</summary>
        public double FirstFrameDtS
        {
            get => _firstFrameDt;
            set
            {
                if (!(value > 0.0 && value <= 10.0))
                    throw new ArgumentOutOfRangeException(nameof(value), value, "must be in (0, 10] s");
                _firstFrameDt = value;
            }
        }

        /// <summary>True once a frame was accepted and the body exists: meshes can be read.</summary>
        public bool HasBody => _accepted;

        /// <summary>Frames the source handed out.</summary>
        public long FramesReceived { get; private set; }

        /// <summary>Frames the library accepted.</summary>
        public long FramesAccepted { get; private set; }

        /// <summary>Frames the library rejected (see <see cref="LastRejection"/>).</summary>
        public long RejectedFrames { get; private set; }

        /// <summary>The most recent rejection (its <see cref="DrapeException.Code"/> and message), or null.</summary>
        public DrapeException? LastRejection { get; private set; }

        /// <summary>Calls to <see cref="Context.Step"/> (or <see cref="Context.Update"/> with no garment).</summary>
        public long Steps { get; private set; }

        /// <summary>The time step given to the last step, in seconds (0 before the first).</summary>
        public float LastStepDtS { get; private set; }

        /// <summary>
        /// One host frame: advances the source by <paramref name="hostDeltaS"/>, pushes its new frame
        /// if there is one, and steps the context (body update and every garment). Returns true if a
        /// new frame was accepted. Before the first accepted frame nothing is stepped. With no
        /// garment, only the body is updated (when there is a new frame). A
        /// <paramref name="hostDeltaS"/> of 0 (a paused game) updates the body but moves no cloth.
        /// </summary>
        public bool Tick(float hostDeltaS)
        {
            if (_context.IsDisposed) throw new ObjectDisposedException(nameof(DressingLoop));
            if (!(hostDeltaS >= 0f) || float.IsInfinity(hostDeltaS))
                throw new ArgumentOutOfRangeException(nameof(hostDeltaS), hostDeltaS, "the frame time must be finite and >= 0");
            _source.Advance(hostDeltaS);

            bool pushed = false;
            double timestamp = 0.0;
            if (_source.TryGetFrame(_joints, out timestamp))
            {
                FramesReceived++;
                try
                {
                    _context.PushSkeleton(_joints, _layout, timestamp);
                    pushed = true;
                    FramesAccepted++;
                }
                catch (DrapeException e) when (IsFrameRejection(e.Code))
                {
                    RejectedFrames++;
                    LastRejection = e;
                }
            }
            if (pushed) _accepted = true;
            if (!_accepted) return false;

            float dt;
            if (Timing == StepTiming.SourceTimestamps)
            {
                if (!pushed) return false;
                double d = _havePrevious ? timestamp - _previousTimestamp : _firstFrameDt;
                dt = (float)Math.Min(Math.Max(d, 1e-6), 10.0);
            }
            else
            {
                dt = Math.Min(hostDeltaS, 10f);
            }
            if (pushed)
            {
                _havePrevious = true;
                _previousTimestamp = timestamp;
            }

            if (_context.Garments.Count == 0 || dt <= 0f)
            {
                if (!pushed) return false;
                _context.Update();
            }
            else
            {
                _context.Step(dt);
                LastStepDtS = dt;
            }
            Steps++;
            return pushed;
        }

        /// <summary>Result codes of drape_context_push_skeleton that mean "this frame is bad", not
        /// "the program is broken".</summary>
        public static bool IsFrameRejection(ResultCode code) =>
            code == ResultCode.NonFinite || code == ResultCode.OutOfRange || code == ResultCode.Timestamp ||
            code == ResultCode.InvalidArgument;

        /// <summary>Disposes the context (and its garments) and, if owned, the source. Idempotent.</summary>
        public void Dispose()
        {
            if (_disposed) return;
            _disposed = true;
            _context.Dispose();
            if (_ownsSource && _source is IDisposable d) d.Dispose();
        }

        private bool _disposed;
    }
}
