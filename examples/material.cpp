// An app's own material on the glass: the runtime builds the refraction map, the app samples it
// in its own shader (docs/integrate.md "Your own material").
//
//   shrefract-example-material BAKE.shrefract.exr
//
// Per frame the app calls Refractor::update() and binds Refractor::refractionMap() (RGBA32F,
// GL_LINEAR, the exit direction xyz and path length w, object space, not normalized) on its
// mesh: Bake::refractionMapMesh(), whose uv address the map. Its shader then does whatever the
// app's renderer does with a direction; here it writes the world exit direction into a second
// draw buffer, and the program checks it against Refractor::draw()'s own at every pixel.
// Only the public headers are used, plus <GL/glcorearb.h> for the app's few GL calls.
#include <GL/glcorearb.h>

#include <cmath>
#include <cstdio>
#include <exception>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "shrefract/context.h"
#include "shrefract/render.h"
#include "shrefract/runtime.h"

// The app's own material: the map sampled at uv, normalized, rotated to world.
static const char* kVertex = R"(#version 330 core
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec2 aUV;
uniform mat4 uModel, uViewProjection;
out vec2 vUV;
void main() {
    vUV = aUV;
    gl_Position = uViewProjection * uModel * vec4(aPosition, 1.0);
}
)";
static const char* kFragment = R"(#version 330 core
uniform sampler2D uRefractionMap;
uniform mat3 uModelRotation;
in vec2 vUV;
layout(location = 0) out vec4 oColor;
layout(location = 1) out vec4 oDirection;
void main() {
    vec3 exitDir = normalize(uModelRotation * texture(uRefractionMap, vUV).xyz);
    oColor = vec4(0.5 + 0.5 * exitDir, 1.0);  // the app would look its environment up here
    oDirection = vec4(exitDir, 1.0);
}
)";

// The few GL functions this app calls, through the context's loader (an app with GLFW, glad or
// libepoxy has them already).
#define APP_GL(X)                                                                                 \
    X(PFNGLCREATESHADERPROC, glCreateShader) X(PFNGLSHADERSOURCEPROC, glShaderSource)              \
    X(PFNGLCOMPILESHADERPROC, glCompileShader) X(PFNGLCREATEPROGRAMPROC, glCreateProgram)          \
    X(PFNGLATTACHSHADERPROC, glAttachShader) X(PFNGLLINKPROGRAMPROC, glLinkProgram)                \
    X(PFNGLGETPROGRAMIVPROC, glGetProgramiv) X(PFNGLUSEPROGRAMPROC, glUseProgram)                  \
    X(PFNGLGETUNIFORMLOCATIONPROC, glGetUniformLocation) X(PFNGLUNIFORM1IPROC, glUniform1i)        \
    X(PFNGLUNIFORMMATRIX3FVPROC, glUniformMatrix3fv) X(PFNGLUNIFORMMATRIX4FVPROC, glUniformMatrix4fv) \
    X(PFNGLGENVERTEXARRAYSPROC, glGenVertexArrays) X(PFNGLBINDVERTEXARRAYPROC, glBindVertexArray)  \
    X(PFNGLGENBUFFERSPROC, glGenBuffers) X(PFNGLBINDBUFFERPROC, glBindBuffer)                      \
    X(PFNGLBUFFERDATAPROC, glBufferData) X(PFNGLENABLEVERTEXATTRIBARRAYPROC, glEnableVertexAttribArray) \
    X(PFNGLVERTEXATTRIBPOINTERPROC, glVertexAttribPointer) X(PFNGLACTIVETEXTUREPROC, glActiveTexture) \
    X(PFNGLBINDTEXTUREPROC, glBindTexture) X(PFNGLDRAWARRAYSPROC, glDrawArrays)                    \
    X(PFNGLENABLEPROC, glEnable)
#define APP_GL_DECLARE(type, name) static type name = nullptr;
APP_GL(APP_GL_DECLARE)

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s BAKE.shrefract.exr\n", argv[0]);
        return 2;
    }
    try {
        const int size = 128;
        auto context = shrefract::createHeadlessContext(shrefract::Backend::Egl);
#define APP_GL_LOAD(type, name) name = reinterpret_cast<type>(context->loader()(#name));
        APP_GL(APP_GL_LOAD)
        shrefract::Bake bake = shrefract::loadBake(argv[1]);
        shrefract::RefractorOptions options;
        options.loader = context->loader();
        auto refractor = shrefract::Refractor::create(bake, options);

        // The app's program and its copy of the map's mesh.
        GLuint program = glCreateProgram();
        for (auto [type, source] : {std::pair{GL_VERTEX_SHADER, kVertex}, {GL_FRAGMENT_SHADER, kFragment}}) {
            GLuint s = glCreateShader(type);
            glShaderSource(s, 1, &source, nullptr);
            glCompileShader(s);
            glAttachShader(program, s);
        }
        glLinkProgram(program);
        GLint linked = 0;
        glGetProgramiv(program, GL_LINK_STATUS, &linked);
        if (!linked) throw std::runtime_error("the app's material does not link");
        const std::vector<shrefract::MapVertex> mesh = bake.refractionMapMesh();
        GLuint vao = 0, vbo = 0;
        glGenVertexArrays(1, &vao);
        glBindVertexArray(vao);
        glGenBuffers(1, &vbo);
        glBindBuffer(GL_ARRAY_BUFFER, vbo);
        glBufferData(GL_ARRAY_BUFFER, mesh.size() * sizeof(shrefract::MapVertex), mesh.data(), GL_STATIC_DRAW);
        const GLsizei stride = sizeof(shrefract::MapVertex);
        for (GLuint a = 0; a < 3; ++a) glEnableVertexAttribArray(a);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, (void*)offsetof(shrefract::MapVertex, position));
        glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride, (void*)offsetof(shrefract::MapVertex, normal));
        glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, stride, (void*)offsetof(shrefract::MapVertex, uv));
        glBindVertexArray(0);

        // One frame: the object turned a little, the camera looking at it.
        const glm::vec3 eye(0.8f, 0.6f, 2.8f);
        const glm::mat4 model = glm::rotate(glm::mat4(1.0f), 0.4f, glm::vec3(0, 1, 0));
        const glm::mat4 view = glm::lookAt(eye, glm::vec3(0.0f), glm::vec3(0, 1, 0));
        const glm::mat4 projection = glm::perspective(glm::radians(45.0f), 1.0f, 0.05f, 50.0f);
        const glm::mat4 viewProjection = projection * view;
        const glm::mat3 rotation(model);
        refractor->update({view, projection, model});
        const GLuint map = refractor->refractionMap();  // built for this update (either path)

        shrefract::OffscreenTarget target(size, size);
        target.bind();
        glEnable(GL_DEPTH_TEST);
        glUseProgram(program);
        glUniformMatrix4fv(glGetUniformLocation(program, "uModel"), 1, GL_FALSE, glm::value_ptr(model));
        glUniformMatrix4fv(glGetUniformLocation(program, "uViewProjection"), 1, GL_FALSE,
                           glm::value_ptr(viewProjection));
        glUniformMatrix3fv(glGetUniformLocation(program, "uModelRotation"), 1, GL_FALSE, glm::value_ptr(rotation));
        glUniform1i(glGetUniformLocation(program, "uRefractionMap"), 0);
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D, map);
        glBindVertexArray(vao);
        glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(mesh.size()));
        glBindVertexArray(0);
        glUseProgram(0);
        const shrefract::RenderedFrame mine = target.read();

        // The runtime's own draw of the same frame, for the check.
        const shrefract::Environment env = shrefract::Environment::fromLatLong(2, 1, std::vector<float>(6, 0.5f));
        target.bind();
        refractor->draw(env);
        const shrefract::RenderedFrame theirs = target.read();

        double worst = 0;
        size_t covered = 0;
        for (size_t i = 0; i < mine.directions.size(); i += 4) {
            if (mine.directions[i + 3] < 0.5f || theirs.directions[i + 3] < 0.5f) continue;
            ++covered;
            const glm::vec3 a(mine.directions[i], mine.directions[i + 1], mine.directions[i + 2]);
            const glm::vec3 b(theirs.directions[i], theirs.directions[i + 1], theirs.directions[i + 2]);
            worst = std::max(worst, std::acos(std::min(1.0, double(glm::dot(a, b)))) * 180.0 / M_PI);
        }
        std::printf("material: %zu pixels, largest angle between the app's exit direction and "
                    "Refractor::draw's: %.4f deg (%s path)\n",
                    covered, worst, shrefract::nameOf(refractor->path()));
        // The same map either way, up to float rounding and the texture unit's sub-texel weights.
        return covered > 500 && worst < 0.1 ? 0 : 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "material: %s\n", e.what());
        return 1;
    }
}
