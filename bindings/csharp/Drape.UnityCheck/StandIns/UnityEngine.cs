// Stand-ins for the UnityEngine members the package's Unity-only scripts use, with Unity's
// signatures (UnityEngine 2021.2+ scripting reference), so those scripts compile and can be run by
// the tests without Unity. Behaviour is the minimum the tests need: a Mesh stores the arrays it is
// given (without copying, so that storing allocates nothing), components live in a GameObject's list.
// Not Unity: lifecycle messages (OnEnable, Update, ...) are called by the tests themselves.
using System;
using System.Collections.Generic;

namespace UnityEngine
{
    public struct Vector3
    {
        public float x, y, z;
        public Vector3(float x, float y, float z) { this.x = x; this.y = y; this.z = z; }
    }

    public class Object
    {
        public string name { get; set; } = "";
        public static void Destroy(Object obj) { if (obj != null) obj.destroyed = true; }
        // Stand-in bookkeeping (Unity has no such member).
        internal bool destroyed;
        public bool IsDestroyedStandIn => destroyed;
    }

    public sealed class GameObject : Object
    {
        private readonly List<Component> _components = new List<Component>();
        public GameObject(string name) { this.name = name; }
        public T AddComponent<T>() where T : Component
        {
            T c = Activator.CreateInstance<T>();
            c.gameObject = this;
            _components.Add(c);
            return c;
        }
        public T GetComponent<T>()
        {
            foreach (Component c in _components)
                if (c is T t) return t;
            return default(T);
        }
    }

    public class Component : Object
    {
        public GameObject gameObject { get; internal set; }
        public T GetComponent<T>() => gameObject != null ? gameObject.GetComponent<T>() : default(T);
    }

    public class Behaviour : Component
    {
        public bool enabled { get; set; } = true;
    }

    public class MonoBehaviour : Behaviour
    {
    }

    public sealed class MeshFilter : Component
    {
        public Mesh sharedMesh { get; set; }
        public Mesh mesh { get => sharedMesh; set => sharedMesh = value; }
    }

    public sealed class TextAsset : Object
    {
        private readonly byte[] _bytes;
        public TextAsset(byte[] bytes) { _bytes = bytes; }   // Unity: TextAsset(string); bytes for the tests
        public byte[] bytes => _bytes;
    }

    public sealed class Mesh : Object
    {
        public Rendering.IndexFormat indexFormat { get; set; } = Rendering.IndexFormat.UInt16;
        public void MarkDynamic() => StandInDynamic = true;
        public void SetVertices(Vector3[] inVertices) { StandInVertices = inVertices; StandInVertexWrites++; }
        public void SetNormals(Vector3[] inNormals) { StandInNormals = inNormals; StandInNormalWrites++; }
        public void SetTriangles(int[] triangles, int submesh, bool calculateBounds)
        {
            if (submesh != 0) throw new ArgumentOutOfRangeException(nameof(submesh));
            if (StandInVertices == null) throw new InvalidOperationException("Unity: vertices must be set before triangles");
            foreach (int i in triangles)
                if (i < 0 || i >= StandInVertices.Length) throw new ArgumentException("Unity: triangle index out of bounds");
            StandInTriangles = triangles;
        }
        public void RecalculateNormals() => StandInRecalculatedNormals++;
        public void RecalculateBounds() => StandInRecalculatedBounds++;

        // Stand-in bookkeeping for the tests (Unity has no such members).
        public bool StandInDynamic;
        public Vector3[] StandInVertices, StandInNormals;
        public int[] StandInTriangles;
        public int StandInVertexWrites, StandInNormalWrites, StandInRecalculatedNormals, StandInRecalculatedBounds;
    }

    public static class Time
    {
        public static float deltaTime { get; set; } = 1f / 60f;   // settable by the tests only
    }

    public static class Application
    {
        public static string streamingAssetsPath { get; set; } = "";
    }

    public static class Debug
    {
        public static readonly List<string> StandInLog = new List<string>();
        public static void Log(object message) => StandInLog.Add("Log: " + message);
        public static void LogWarning(object message) => StandInLog.Add("Warning: " + message);
        public static void LogError(object message) => StandInLog.Add("Error: " + message);
        public static void LogError(object message, Object context) => StandInLog.Add("Error: " + message);
    }

    [AttributeUsage(AttributeTargets.Field)]
    public sealed class SerializeField : Attribute { }

    [AttributeUsage(AttributeTargets.Field, AllowMultiple = true)]
    public sealed class TooltipAttribute : Attribute { public TooltipAttribute(string tooltip) { } }

    [AttributeUsage(AttributeTargets.Field, AllowMultiple = true)]
    public sealed class HeaderAttribute : Attribute { public HeaderAttribute(string header) { } }

    [AttributeUsage(AttributeTargets.Field)]
    public sealed class RangeAttribute : Attribute { public RangeAttribute(float min, float max) { } }

    [AttributeUsage(AttributeTargets.Class)]
    public sealed class DisallowMultipleComponent : Attribute { }

    [AttributeUsage(AttributeTargets.Class)]
    public sealed class AddComponentMenu : Attribute { public AddComponentMenu(string menuName) { } }

    [AttributeUsage(AttributeTargets.Method)]
    public sealed class RuntimeInitializeOnLoadMethodAttribute : Attribute { }
}

namespace UnityEngine.Rendering
{
    public enum IndexFormat
    {
        UInt16 = 0,
        UInt32 = 1,
    }
}
