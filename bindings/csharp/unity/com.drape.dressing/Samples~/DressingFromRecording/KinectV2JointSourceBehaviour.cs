// Drape sample (Unity, Windows): joints from a live Kinect v2 through the Kinect for Windows SDK 2.0
// Unity plug-in (Kinect.2.0.1410.19000.unitypackage: namespace Windows.Kinect). Compiled only with
// the scripting define DRAPE_KINECT_V2 (Player Settings > Other Settings > Scripting Define Symbols),
// so the sample compiles without the SDK. Mapping (docs/unity.md): JointType 0..24 is Drape's
// Kinect2 layout order; CameraSpacePoint is metres, right-handed, as Drape wants; TrackingState
// NotTracked/Inferred/Tracked = 0/1/2 as Drape's.
#if DRAPE_KINECT_V2
using System;
using System.Diagnostics;
using Drape;
using UnityEngine;
using Kinect = Windows.Kinect;

namespace Drape.Samples
{
    /// <summary>The tracked body the sensor saw first (kept while it stays tracked) as an
    /// <see cref="IJointSource"/> in <see cref="Layout.Kinect2"/>.</summary>
    [AddComponentMenu("Drape/Kinect v2 Joint Source")]
    public sealed class KinectV2JointSourceBehaviour : MonoBehaviour, IJointSource
    {
        private const int JointCountV2 = 25;
        private Kinect.KinectSensor _sensor;
        private Kinect.BodyFrameReader _reader;
        private Kinect.Body[] _bodies;
        private ulong _trackingId;
        private double _lastTimestamp = double.NegativeInfinity;

        public Layout Layout => Layout.Kinect2;
        public int JointCount => JointCountV2;

        private void OnEnable()
        {
            _sensor = Kinect.KinectSensor.GetDefault();
            if (_sensor == null) return;
            _reader = _sensor.BodyFrameSource.OpenReader();
            if (!_sensor.IsOpen) _sensor.Open();
            _bodies = new Kinect.Body[_sensor.BodyFrameSource.BodyCount];
        }

        private void OnDisable()
        {
            if (_reader != null) _reader.Dispose();
            _reader = null;
            if (_sensor != null && _sensor.IsOpen) _sensor.Close();
            _sensor = null;
        }

        public void Advance(double deltaS) { }   // a live sensor has its own clock

        public bool TryGetFrame(Span<Joint> joints, out double timestampS)
        {
            timestampS = 0.0;
            if (_reader == null) return false;
            Kinect.BodyFrame frame = _reader.AcquireLatestFrame();
            if (frame == null) return false;
            // Host time at acquisition: strictly increasing, in seconds. (BodyFrame.RelativeTime is
            // the sensor's own clock and may be used instead where the plug-in exposes it.)
            double t = Stopwatch.GetTimestamp() / (double)Stopwatch.Frequency;
            try
            {
                frame.GetAndRefreshBodyData(_bodies);
            }
            finally
            {
                frame.Dispose();
            }
            Kinect.Body body = Pick();
            if (body == null || t <= _lastTimestamp) return false;

            // Note: the plug-in's Body.Joints builds a new dictionary per call (it allocates).
            var map = body.Joints;
            for (int i = 0; i < JointCountV2; ++i)
            {
                Kinect.Joint k = map[(Kinect.JointType)i];
                joints[i] = new Joint(new Vector3f(k.Position.X, k.Position.Y, k.Position.Z),
                                      (TrackingState)(int)k.TrackingState);
            }
            _lastTimestamp = t;
            timestampS = t;
            return true;
        }

        // The body followed so far while it is tracked, else the first tracked one.
        private Kinect.Body Pick()
        {
            Kinect.Body first = null;
            foreach (Kinect.Body b in _bodies)
            {
                if (b == null || !b.IsTracked) continue;
                if (b.TrackingId == _trackingId) return b;
                if (first == null) first = b;
            }
            if (first != null) _trackingId = first.TrackingId;
            return first;
        }
    }
}
#endif
