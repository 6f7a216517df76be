// Drape sample: joints from an Azure Kinect through the Body Tracking SDK's C# API
// (Microsoft.Azure.Kinect.BodyTracking). Compiled only with the scripting define DRAPE_AZURE_KINECT.
// The host runs the usual capture loop (Device.GetCapture -> Tracker.EnqueueCapture, as in Microsoft's
// sample_unity_bodytracking); this source pops the tracker's results. Mapping (docs/unity.md):
// JointId 0..31 is Drape's Azure layout order; positions are millimetres in the depth camera's
// right-handed space (+Y down), so they are divided by 1 000 and need no axis flip; confidence
// None/Low/Medium/High -> NotTracked/Inferred/Tracked/Tracked.
#if DRAPE_AZURE_KINECT
using System;
using Drape;
using K4ABT = Microsoft.Azure.Kinect.BodyTracking;

namespace Drape.Samples
{
    /// <summary>The body the tracker reported first (kept while it is reported) as an
    /// <see cref="IJointSource"/> in <see cref="Layout.Azure"/>. Not a MonoBehaviour: give it to
    /// <see cref="DrapeDresser.JointSource"/> from the script that owns the tracker.</summary>
    public sealed class AzureKinectJointSource : IJointSource
    {
        private const int JointCountAzure = 32;
        private readonly K4ABT.Tracker _tracker;
        private uint _bodyId;
        private bool _haveBody;
        private double _lastTimestamp = double.NegativeInfinity;

        public AzureKinectJointSource(K4ABT.Tracker tracker)
        {
            _tracker = tracker ?? throw new ArgumentNullException(nameof(tracker));
        }

        public Layout Layout => Layout.Azure;
        public int JointCount => JointCountAzure;

        public void Advance(double deltaS) { }   // the device has its own clock

        public bool TryGetFrame(Span<Joint> joints, out double timestampS)
        {
            timestampS = 0.0;
            using (K4ABT.Frame frame = _tracker.PopResult(TimeSpan.Zero, throwOnTimeout: false))
            {
                if (frame == null || frame.NumberOfBodies == 0) return false;
                uint index = 0;
                if (_haveBody)
                {
                    for (uint i = 0; i < frame.NumberOfBodies; ++i)
                        if (frame.GetBodyId(i) == _bodyId) { index = i; break; }
                }
                _bodyId = frame.GetBodyId(index);
                _haveBody = true;

                double t = frame.DeviceTimestamp.TotalSeconds;
                if (t <= _lastTimestamp) return false;
                K4ABT.Skeleton skeleton = frame.GetBodySkeleton(index);
                for (int j = 0; j < JointCountAzure; ++j)
                {
                    K4ABT.Joint k = skeleton.GetJoint((K4ABT.JointId)j);
                    var state = k.ConfidenceLevel == K4ABT.JointConfidenceLevel.None ? TrackingState.NotTracked
                              : k.ConfidenceLevel == K4ABT.JointConfidenceLevel.Low ? TrackingState.Inferred
                              : TrackingState.Tracked;
                    joints[j] = new Joint(new Vector3f(k.Position.X * 0.001f, k.Position.Y * 0.001f, k.Position.Z * 0.001f), state);
                }
                _lastTimestamp = t;
                timestampS = t;
                return true;
            }
        }
    }
}
#endif
