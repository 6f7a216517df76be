using System;
using System.Runtime.InteropServices;

namespace Drape
{
    /// <summary>
    /// A skeleton recording read whole into memory (drape_recording): Kinect CSV, BVH or Drape's
    /// own format. Owns its native handle: call <see cref="Dispose"/>. One thread at a time.
    /// Like <see cref="Context"/>, a recording garbage-collected without Dispose is reported as a
    /// leak (<see cref="DrapeLibrary.LeakedHandleCount"/>), never freed from the finalizer.
    /// </summary>
    public sealed unsafe class Recording : IDisposable
    {
        private IntPtr _handle;

        /// <summary>What the recording holds (read once when it was opened).</summary>
        public RecordingInfo Info { get; }

        private Recording(IntPtr handle)
        {
            _handle = handle;
            try
            {
                RecordingInfo info = default;
                info.StructSize = (uint)sizeof(RecordingInfo);
                DrapeException.Check(Native.drape_recording_get_info(handle, &info));
                Info = info;
            }
            catch
            {
                Dispose();
                throw;
            }
        }

        /// <summary>Reads a recording file (drape_recording_open). <paramref name="layout"/>:
        /// <see cref="Layout.Auto"/>, or the layout the file must have. Paths are passed as UTF-8.</summary>
        public static Recording Open(string path, Layout layout = Layout.Auto)
        {
            byte[] utf8 = Utf8.ToNative(path, nameof(path));
            DrapeLibrary.EnsureCompatible();
            IntPtr h;
            fixed (byte* p = utf8)
                DrapeException.Check(Native.drape_recording_open(p, (int)layout, &h));
            return new Recording(h);
        }

        /// <summary>Reads a recording from memory (drape_recording_open_memory; the bytes are copied).</summary>
        public static Recording OpenMemory(ReadOnlySpan<byte> data, Layout layout = Layout.Auto)
        {
            DrapeLibrary.EnsureCompatible();
            IntPtr h;
            fixed (byte* p0 = &MemoryMarshal.GetReference(data))   // not `fixed (p = data)`: see Pinning.cs
                DrapeException.Check(Native.drape_recording_open_memory(Pinning.OrNull(p0, data.Length),
                                                                         (UIntPtr)(uint)data.Length, (int)layout, &h));
            return new Recording(h);
        }

        /// <summary>The native drape_recording*, or <see cref="IntPtr.Zero"/> once disposed.</summary>
        public IntPtr Handle => _handle;

        /// <summary>True once <see cref="Dispose"/> has run.</summary>
        public bool IsDisposed => _handle == IntPtr.Zero;

        /// <summary>Destroys the native recording (drape_recording_destroy). Idempotent.</summary>
        public void Dispose()
        {
            IntPtr h = _handle;
            if (h == IntPtr.Zero) return;
            _handle = IntPtr.Zero;
            GC.SuppressFinalize(this);
            Native.drape_recording_destroy(h);
        }

        /// <summary>Only reports the leak; never calls native code.</summary>
        ~Recording()
        {
            if (_handle != IntPtr.Zero) DrapeLibrary.ReportLeak(nameof(Recording));
        }

        private IntPtr Live
        {
            get
            {
                IntPtr h = _handle;
                if (h == IntPtr.Zero) throw new ObjectDisposedException(nameof(Recording));
                return h;
            }
        }

        /// <summary>Copies frame <paramref name="index"/> (0-based) into <paramref name="joints"/>
        /// (at least <see cref="RecordingInfo.JointCount"/> long) and its timestamp in seconds from the
        /// recording's start into <paramref name="timestampS"/>.</summary>
        public void ReadFrame(int index, Span<Joint> joints, out double timestampS)
        {
            IntPtr h = Live;
            if (index < 0) throw new ArgumentOutOfRangeException(nameof(index), index, "frame index must be >= 0");
            double t = 0.0;
            fixed (Joint* p = joints)
                DrapeException.Check(Native.drape_recording_read_frame(h, (uint)index, p, (uint)joints.Length, &t));
            timestampS = t;
        }

        /// <summary>Writes the recording in Drape's own text format (drape_recording_save).</summary>
        public void Save(string path)
        {
            IntPtr h = Live;
            byte[] utf8 = Utf8.ToNative(path, nameof(path));
            fixed (byte* p = utf8)
                DrapeException.Check(Native.drape_recording_save(h, p));
        }
    }
}
