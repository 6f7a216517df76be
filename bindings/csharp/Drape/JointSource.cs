using System;

namespace Drape
{
    /// <summary>
    /// Where a <see cref="DressingLoop"/> gets skeleton frames from: a recording
    /// (<see cref="RecordingJointSource"/>), a live sensor (a Kinect v2 or Azure Kinect body tracker
    /// wrapped by the host: docs/unity.md has the mappings), a network stream, a test.
    /// <para>The loop calls, once per host frame and on its own thread: <see cref="Advance"/> with the
    /// host's frame time, then <see cref="TryGetFrame"/>. Neither should allocate in the steady state.</para>
    /// </summary>
    public interface IJointSource
    {
        /// <summary>The layout of every frame (<see cref="Drape.Layout.Kinect1"/>,
        /// <see cref="Drape.Layout.Kinect2"/> or <see cref="Drape.Layout.Azure"/>; never Auto).</summary>
        Layout Layout { get; }

        /// <summary>Joints per frame: the layout's count (20, 25 or 32).</summary>
        int JointCount { get; }

        /// <summary>The host's clock moved on by <paramref name="deltaS"/> seconds (&gt;= 0). Live
        /// sources may ignore it; a recording uses it to play back at the recorded speed.</summary>
        void Advance(double deltaS);

        /// <summary>Copies the newest frame not returned before into <paramref name="joints"/>
        /// (<see cref="JointCount"/> long, in the layout's order, metres in a right-handed camera
        /// space) and its time in seconds (strictly increasing from frame to frame) and returns
        /// true; returns false when there is no new frame (nothing written).</summary>
        bool TryGetFrame(Span<Joint> joints, out double timestampS);
    }

    /// <summary>How a <see cref="RecordingJointSource"/> hands out frames.</summary>
    public enum PlaybackMode
    {
        /// <summary>At the recorded speed: a frame becomes due when the time passed to
        /// <see cref="IJointSource.Advance"/> (times <see cref="RecordingJointSource.Speed"/>) reaches
        /// its timestamp; when the host is slower than the recording, the newest due frame is
        /// returned and the ones before it are skipped (as a live sensor would).</summary>
        RealTime = 0,
        /// <summary>One frame per <see cref="IJointSource.TryGetFrame"/> call, whatever the host's
        /// clock says (offline processing, tests, drape-replay's behaviour).</summary>
        EveryCall = 1,
    }

    /// <summary>
    /// An <see cref="IJointSource"/> over a <see cref="Recording"/> (Kinect CSV, BVH, .drec).
    /// Timestamps are made to start at 0 and, when <see cref="Loop"/> is on, keep increasing across
    /// repetitions (each repetition starts one nominal frame period after the previous one's last
    /// frame). No managed allocation after construction. One thread at a time.
    /// </summary>
    public sealed class RecordingJointSource : IJointSource, IDisposable
    {
        private readonly Recording _recording;
        private readonly bool _ownsRecording;
        private readonly double[] _times;       // frame timestamps relative to the first frame
        private readonly double _period;        // one nominal frame period (s)
        private readonly double _cycle;         // one repetition: last timestamp + one period
        private int _next;                      // the next frame index to hand out
        private int _repetition;                // completed repetitions (loop)
        private double _clock;                  // playback time within the current repetition (RealTime)

        /// <summary>Plays <paramref name="recording"/>. With <paramref name="ownsRecording"/>,
        /// <see cref="Dispose"/> disposes it too.</summary>
        public RecordingJointSource(Recording recording, bool ownsRecording = false)
        {
            _recording = recording ?? throw new ArgumentNullException(nameof(recording));
            RecordingInfo info = recording.Info;
            if (info.FrameCount == 0) throw new ArgumentException("the recording holds no frames", nameof(recording));
            _ownsRecording = ownsRecording;
            _times = new double[info.FrameCount];
            var joints = new Joint[info.JointCount];
            double first = 0.0;
            for (int i = 0; i < _times.Length; ++i)
            {
                recording.ReadFrame(i, joints, out double t);
                if (i == 0) first = t;
                _times[i] = t - first;
            }
            _period = float.IsFinite(info.NominalRateHz) && info.NominalRateHz > 0f ? 1.0 / info.NominalRateHz : 1.0 / 30.0;
            _cycle = _times[_times.Length - 1] + _period;
        }

        /// <summary>Opens <paramref name="path"/> (<see cref="Recording.Open"/>) and plays it; the
        /// source owns the recording.</summary>
        public static RecordingJointSource Open(string path, Layout layout = Layout.Auto)
        {
            Recording rec = Recording.Open(path, layout);
            try { return new RecordingJointSource(rec, ownsRecording: true); }
            catch { rec.Dispose(); throw; }
        }

        /// <summary>Reads a recording from memory (<see cref="Recording.OpenMemory"/>, e.g. a Unity
        /// TextAsset's bytes) and plays it; the source owns the recording.</summary>
        public static RecordingJointSource OpenMemory(ReadOnlySpan<byte> data, Layout layout = Layout.Auto)
        {
            Recording rec = Recording.OpenMemory(data, layout);
            try { return new RecordingJointSource(rec, ownsRecording: true); }
            catch { rec.Dispose(); throw; }
        }

        /// <summary>The recording played.</summary>
        public Recording Recording => _recording;

        /// <summary>See <see cref="PlaybackMode"/>. Default <see cref="PlaybackMode.RealTime"/>.</summary>
        public PlaybackMode Mode { get; set; } = PlaybackMode.RealTime;

        /// <summary>Start again after the last frame (default true); else <see cref="TryGetFrame"/>
        /// returns false from then on.</summary>
        public bool Loop { get; set; } = true;

        /// <summary>Playback speed for <see cref="PlaybackMode.RealTime"/> (default 1; &gt;= 0).</summary>
        public double Speed
        {
            get => _speed;
            set
            {
                if (!(value >= 0.0) || double.IsInfinity(value))
                    throw new ArgumentOutOfRangeException(nameof(value), value, "speed must be finite and >= 0");
                _speed = value;
            }
        }
        private double _speed = 1.0;

        /// <summary>The recording's nominal frame period in seconds (1 / its median rate; 1/30 if unknown).</summary>
        public double FramePeriodS => _period;

        /// <summary>The index of the next frame to be handed out (0-based, within the recording).</summary>
        public int NextFrameIndex => _next;

        /// <summary>How many times playback went back to the first frame.</summary>
        public int Repetitions => _repetition;

        /// <summary>True when <see cref="Loop"/> is off and every frame has been handed out.</summary>
        public bool IsFinished => !Loop && _next >= _times.Length;

        /// <inheritdoc/>
        public Layout Layout => _recording.Info.Layout;

        /// <inheritdoc/>
        public int JointCount => (int)_recording.Info.JointCount;

        /// <summary>Goes back to the first frame and time 0 (timestamps keep increasing: the
        /// context requires it).</summary>
        public void Rewind()
        {
            if (_next > 0 || _clock > 0.0) ++_repetition;
            _next = 0;
            _clock = 0.0;
        }

        /// <inheritdoc/>
        public void Advance(double deltaS)
        {
            if (!(deltaS >= 0.0) || double.IsInfinity(deltaS))
                throw new ArgumentOutOfRangeException(nameof(deltaS), deltaS, "the time step must be finite and >= 0");
            if (Mode == PlaybackMode.RealTime) _clock += deltaS * _speed;
        }

        /// <inheritdoc/>
        public bool TryGetFrame(Span<Joint> joints, out double timestampS)
        {
            timestampS = 0.0;
            if (_recording.IsDisposed) throw new ObjectDisposedException(nameof(RecordingJointSource));
            int index;
            if (Mode == PlaybackMode.EveryCall)
            {
                if (_next >= _times.Length)
                {
                    if (!Loop) return false;
                    ++_repetition;
                    _next = 0;
                }
                index = _next;
            }
            else
            {
                if (_clock >= _cycle && Loop)
                {
                    // Wrap into the current repetition; frames of skipped repetitions are dropped.
                    int wraps = (int)Math.Floor(_clock / _cycle);
                    _repetition += wraps;
                    _clock -= wraps * _cycle;
                    _next = 0;
                }
                // The newest frame that is due.
                int due = NewestAtOrBefore(_clock);
                if (due < _next) return false;
                index = due;
            }
            _recording.ReadFrame(index, joints, out _);
            _next = index + 1;
            timestampS = _repetition * _cycle + _times[index];
            return true;
        }

        private int NewestAtOrBefore(double t)
        {
            // Binary search: the last i with _times[i] <= t, or -1.
            int lo = 0, hi = _times.Length - 1, found = -1;
            while (lo <= hi)
            {
                int mid = (lo + hi) >> 1;
                if (_times[mid] <= t) { found = mid; lo = mid + 1; }
                else hi = mid - 1;
            }
            return found;
        }

        /// <summary>Disposes the recording if the source owns it.</summary>
        public void Dispose()
        {
            if (_ownsRecording) _recording.Dispose();
        }
    }
}
