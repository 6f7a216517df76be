// Stand-ins for the sensor SDK members the package's sample sources use, with the SDKs' signatures,
// so those sources (behind DRAPE_KINECT_V2 / DRAPE_AZURE_KINECT) compile without the SDKs:
//  - Kinect for Windows SDK 2.0 Unity plug-in, namespace Windows.Kinect;
//  - Azure Kinect Body Tracking SDK C# API, namespace Microsoft.Azure.Kinect.BodyTracking.
// They only check that the samples use those APIs consistently with these declarations; they are
// not the SDKs (the tests feed them synthetic bodies).
using System;
using System.Collections.Generic;

namespace Windows.Kinect
{
    public enum JointType
    {
        SpineBase = 0, SpineMid = 1, Neck = 2, Head = 3, ShoulderLeft = 4, ElbowLeft = 5, WristLeft = 6,
        HandLeft = 7, ShoulderRight = 8, ElbowRight = 9, WristRight = 10, HandRight = 11, HipLeft = 12,
        KneeLeft = 13, AnkleLeft = 14, FootLeft = 15, HipRight = 16, KneeRight = 17, AnkleRight = 18,
        FootRight = 19, SpineShoulder = 20, HandTipLeft = 21, ThumbLeft = 22, HandTipRight = 23, ThumbRight = 24,
    }

    public enum TrackingState { NotTracked = 0, Inferred = 1, Tracked = 2 }

    public struct CameraSpacePoint { public float X; public float Y; public float Z; }

    public struct Joint
    {
        public JointType JointType;
        public CameraSpacePoint Position;
        public TrackingState TrackingState;
    }

    public sealed class Body
    {
        public bool IsTracked { get; set; }
        public ulong TrackingId { get; set; }
        public Dictionary<JointType, Joint> Joints { get; set; } = new Dictionary<JointType, Joint>();
    }

    public sealed class BodyFrame : IDisposable
    {
        internal Body[] StandInBodies;
        public void GetAndRefreshBodyData(IList<Body> bodies)
        {
            for (int i = 0; i < bodies.Count && i < StandInBodies.Length; ++i) bodies[i] = StandInBodies[i];
        }
        public void Dispose() { }
    }

    public sealed class BodyFrameReader : IDisposable
    {
        internal readonly Queue<BodyFrame> StandInFrames = new Queue<BodyFrame>();
        public BodyFrame AcquireLatestFrame() => StandInFrames.Count > 0 ? StandInFrames.Dequeue() : null;
        public void Dispose() { }
    }

    public sealed class BodyFrameSource
    {
        internal readonly BodyFrameReader StandInReader = new BodyFrameReader();
        public int BodyCount => 6;
        public BodyFrameReader OpenReader() => StandInReader;
    }

    public sealed class KinectSensor
    {
        private static readonly KinectSensor s_default = new KinectSensor();
        public static KinectSensor GetDefault() => s_default;
        public bool IsOpen { get; private set; }
        public BodyFrameSource BodyFrameSource { get; } = new BodyFrameSource();
        public void Open() => IsOpen = true;
        public void Close() => IsOpen = false;

        /// <summary>Stand-in only: queues a frame holding these bodies.</summary>
        public static void StandInQueue(params Body[] bodies) =>
            s_default.BodyFrameSource.StandInReader.StandInFrames.Enqueue(new BodyFrame { StandInBodies = bodies });
    }
}

namespace Microsoft.Azure.Kinect.BodyTracking
{
    public enum JointId
    {
        Pelvis = 0, SpineNavel, SpineChest, Neck, ClavicleLeft, ShoulderLeft, ElbowLeft, WristLeft, HandLeft,
        HandTipLeft, ThumbLeft, ClavicleRight, ShoulderRight, ElbowRight, WristRight, HandRight, HandTipRight,
        ThumbRight, HipLeft, KneeLeft, AnkleLeft, FootLeft, HipRight, KneeRight, AnkleRight, FootRight, Head,
        Nose, EyeLeft, EarLeft, EyeRight, EarRight, Count,
    }

    public enum JointConfidenceLevel { None = 0, Low = 1, Medium = 2, High = 3, Count = 4 }

    public struct Joint
    {
        public System.Numerics.Vector3 Position;
        public System.Numerics.Quaternion Quaternion;
        public JointConfidenceLevel ConfidenceLevel;
    }

    public struct Skeleton
    {
        internal Joint[] StandInJoints;
        public Joint GetJoint(JointId jointId) => StandInJoints[(int)jointId];
    }

    public sealed class Frame : IDisposable
    {
        internal Skeleton[] StandInSkeletons = Array.Empty<Skeleton>();
        internal uint[] StandInIds = Array.Empty<uint>();
        public uint NumberOfBodies => (uint)StandInSkeletons.Length;
        public TimeSpan DeviceTimestamp { get; internal set; }
        public Skeleton GetBodySkeleton(uint index) => StandInSkeletons[index];
        public uint GetBodyId(uint index) => StandInIds[index];
        public void Dispose() { }
    }

    public sealed class Tracker : IDisposable
    {
        private readonly Queue<Frame> _results = new Queue<Frame>();
        public Frame PopResult(TimeSpan timeout, bool throwOnTimeout = true)
        {
            if (_results.Count > 0) return _results.Dequeue();
            if (throwOnTimeout) throw new TimeoutException();
            return null;
        }
        public void Dispose() { }

        /// <summary>Stand-in only: queues a result with one body.</summary>
        public void StandInQueue(TimeSpan deviceTimestamp, uint bodyId, Joint[] joints) =>
            _results.Enqueue(new Frame
            {
                DeviceTimestamp = deviceTimestamp,
                StandInSkeletons = new[] { new Skeleton { StandInJoints = joints } },
                StandInIds = new[] { bodyId },
            });
    }
}
