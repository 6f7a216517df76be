// Unity-only: a recording as a component that DrapeDresser (or any script) can take joints from.
using System;
using System.IO;
using UnityEngine;

namespace Drape
{
    /// <summary>
    /// Plays a skeleton recording (a Kinect v2 CSV as a TextAsset, or a file: Kinect CSV, BVH, .drec)
    /// as an <see cref="IJointSource"/>, at the recorded speed (<see cref="PlaybackMode.RealTime"/>),
    /// looping. The recording is read when a joint source property is first used and freed in
    /// OnDestroy.
    /// </summary>
    [AddComponentMenu("Drape/Recording Joint Source")]
    public sealed class RecordingJointSourceBehaviour : MonoBehaviour, IJointSource
    {
        [Tooltip("A recording imported as a TextAsset (a .csv; rename a .bvh or .drec file to .bytes). Used when set.")]
        [SerializeField] private TextAsset recording = null;

        [Tooltip("Else a file: an absolute path, or one relative to Application.streamingAssetsPath (not on Android or WebGL, where StreamingAssets are not files).")]
        [SerializeField] private string path = "";

        [Tooltip("Start again after the last frame.")]
        [SerializeField] private bool loop = true;

        [Tooltip("Playback speed (1 = as recorded).")]
        [SerializeField] private float speed = 1f;

        private RecordingJointSource _source;

        /// <summary>The playing source (opened on first use).</summary>
        public RecordingJointSource Source
        {
            get
            {
                if (_source == null) _source = Open();
                return _source;
            }
        }

        private RecordingJointSource Open()
        {
            RecordingJointSource s;
            if (recording != null)
            {
                s = RecordingJointSource.OpenMemory(recording.bytes);
            }
            else if (!string.IsNullOrEmpty(path))
            {
                string full = Path.IsPathRooted(path) ? path : Path.Combine(Application.streamingAssetsPath, path);
                s = RecordingJointSource.Open(full);
            }
            else
            {
                throw new InvalidOperationException($"{name}: RecordingJointSourceBehaviour has neither a recording TextAsset nor a path");
            }
            s.Loop = loop;
            s.Speed = speed;
            s.Mode = PlaybackMode.RealTime;
            return s;
        }

        /// <inheritdoc/>
        public Layout Layout => Source.Layout;
        /// <inheritdoc/>
        public int JointCount => Source.JointCount;
        /// <inheritdoc/>
        public void Advance(double deltaS) => Source.Advance(deltaS);
        /// <inheritdoc/>
        public bool TryGetFrame(Span<Joint> joints, out double timestampS) => Source.TryGetFrame(joints, out timestampS);

        private void OnDestroy()
        {
            if (_source != null) _source.Dispose();
            _source = null;
        }
    }
}
