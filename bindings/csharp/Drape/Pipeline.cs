// The Adaptive pipeline section of drape.h (docs/adaptive.md): what a context skips when the scene
// does not need it, and what it skipped. Structs mirror drape.h byte for byte (StructLayoutTests).
using System;
using System.Runtime.InteropServices;

namespace Drape
{
    /// <summary>drape_pipeline_stage: bits of <see cref="SkipStats.StagesSkippedLast"/>.</summary>
    [Flags]
    public enum PipelineStage : int
    {
        /// <summary>DRAPE_STAGE_BODY_MESH: body vertex positions.</summary>
        BodyMesh = 1,
        /// <summary>DRAPE_STAGE_BODY_NORMALS: body vertex normals.</summary>
        BodyNormals = 2,
        /// <summary>DRAPE_STAGE_PROXIES: some tracking ellipsoids (culled).</summary>
        Proxies = 4,
        /// <summary>DRAPE_STAGE_CLOTH: some garment's step (asleep).</summary>
        Cloth = 8,
    }

    /// <summary>drape_pipeline_options: start from <see cref="CreateDefault"/> (everything adaptive on).</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct PipelineOptions
    {
        /// <summary>struct_size: sizeof(drape_pipeline_options).</summary>
        public uint StructSize;
        /// <summary>cull_proxies: 1 = build only the ellipsoids some awake garment can reach (default).</summary>
        public uint CullProxies;
        /// <summary>stages_on_demand: 1 = body mesh and normals only when read or measured (default).</summary>
        public uint StagesOnDemand;
        /// <summary>sleep: 1 = still garments on a still body skip their steps (default).</summary>
        public uint Sleep;
        /// <summary>sleep_delay_s: stillness before a garment sleeps, [0, 60]; 0.5.</summary>
        public float SleepDelayS;
        /// <summary>sleep_distance_m: joints within this of where they were are still, [0, 1]; 0.005.</summary>
        public float SleepDistanceM;
        /// <summary>sleep_speed_m_s: particles slower than this are still, [0, 10]; 0.02.</summary>
        public float SleepSpeedMS;
        /// <summary>reach_margin_m: added to each garment's reach, [0, 2]; 0.1.</summary>
        public float ReachMarginM;
        /// <summary>reserved: must be 0.</summary>
        public uint Reserved;

        /// <summary>The library's defaults (drape_pipeline_options_init).</summary>
        public static unsafe PipelineOptions CreateDefault()
        {
            DrapeLibrary.EnsureCompatible();
            PipelineOptions o;
            DrapeException.Check(Native.drape_pipeline_options_init(&o));
            return o;
        }

        /// <summary>Every adaptive option off: every stage every frame (a host that reads everything
        /// every frame, or a comparison run).</summary>
        public static PipelineOptions CreateFull()
        {
            PipelineOptions o = CreateDefault();
            o.CullProxies = 0;
            o.StagesOnDemand = 0;
            o.Sleep = 0;
            return o;
        }
    }

    /// <summary>drape_skip_stats: what the adaptive pipeline skipped.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct SkipStats
    {
        /// <summary>struct_size.</summary>
        public uint StructSize;
        /// <summary>proxies_available: tracking ellipsoids the body has.</summary>
        public uint ProxiesAvailable;
        /// <summary>proxies_built: of which the last update built.</summary>
        public uint ProxiesBuilt;
        /// <summary>stages_skipped_last: <see cref="PipelineStage"/> bits skipped in the last frame so far.</summary>
        public uint StagesSkippedLast;
        /// <summary>garments in the context.</summary>
        public uint Garments;
        /// <summary>garments_asleep now.</summary>
        public uint GarmentsAsleep;
        /// <summary>updates that built the body for a new frame.</summary>
        public ulong Updates;
        /// <summary>stages_skipped: stage runs skipped so far.</summary>
        public ulong StagesSkipped;
        /// <summary>proxies_skipped: ellipsoid builds skipped so far.</summary>
        public ulong ProxiesSkipped;
        /// <summary>steps with at least one garment.</summary>
        public ulong Steps;
        /// <summary>frames_slept: steps in which every garment slept.</summary>
        public ulong FramesSlept;
        /// <summary>garment_steps_slept: garment steps skipped.</summary>
        public ulong GarmentStepsSlept;

        /// <summary>The stages skipped in the last frame, as flags.</summary>
        public PipelineStage LastSkipped => (PipelineStage)StagesSkippedLast;
    }

    public sealed unsafe partial class Context
    {
        /// <summary>The adaptive pipeline's options (drape_context_get_pipeline_options / _set_pipeline_options).
        /// Setting validates them as a whole (a rejected value changes nothing) and wakes every garment.</summary>
        public PipelineOptions PipelineOptions
        {
            get
            {
                IntPtr h = Live;
                PipelineOptions o = default;
                o.StructSize = (uint)sizeof(PipelineOptions);
                DrapeException.Check(Native.drape_context_get_pipeline_options(h, &o));
                return o;
            }
            set
            {
                IntPtr h = Live;
                PipelineOptions o = value;
                DrapeException.Check(Native.drape_context_set_pipeline_options(h, &o));
            }
        }

        /// <summary>Wakes every sleeping garment: the next step runs them all (drape_context_wake).</summary>
        public void Wake()
        {
            IntPtr h = Live;
            DrapeException.Check(Native.drape_context_wake(h));
        }

        /// <summary>What the adaptive pipeline skipped (drape_context_get_skip_stats).</summary>
        public SkipStats GetSkipStats()
        {
            IntPtr h = Live;
            SkipStats s = default;
            s.StructSize = (uint)sizeof(SkipStats);
            DrapeException.Check(Native.drape_context_get_skip_stats(h, &s));
            return s;
        }
    }
}
